# SPDX-License-Identifier: Apache-2.0
"""The pipeline's ``run(cfg)``: prepare the run directory, run the stages, write the summary.

Used by ``full_pipeline.py`` (all selected stages) and by each ``workflows/<stage>.py`` (one stage), so a
stage run on its own gets the same run directory, manifest, skip/resume and time box.
"""

from __future__ import annotations

import copy
import sys
import time
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf

from workflows import stage_registry
from workflows.manifest import Manifest, StageStatus
from workflows.pipeline_report import console, print_ending, print_header, say, stage_line, stage_progress
from workflows.run_dir import (
    RunDir,
    atomic_write_json,
    atomic_write_text,
    atomic_write_yaml,
    config_hash,
    seed_everything,
    write_git_state,
)
from workflows.run_guard import run_dir_problem
from workflows.run_log import job_log_path, library_output_to
from workflows.run_summary import SMOKE_CONSOLE_NOTE, headline, summary_markdown
from workflows.schemas import REPO_ROOT
from workflows.stage_hashing import hashable_config, stage_hashes
from workflows.stage_registry import StageSpec
from workflows.stage_runner import PipelineConfigError, StageOutcome, StageRunner, resolve_device, validate_selection
from workflows.tracking import Tracker

__all__ = ["EXIT_FAILED", "EXIT_INCOMPLETE", "EXIT_OK", "exit_code", "run_from_hydra", "run_pipeline"]

EXIT_OK = 0
"""Every selected stage is done, skipped, not implemented or blocked."""
EXIT_FAILED = 1
"""A stage raised an error."""
EXIT_INCOMPLETE = 3
"""A stage hit its time box (or the pipeline's): rerun the same command to continue."""


def exit_code(outcomes: Sequence[StageOutcome]) -> int:
    """Map the stages' outcomes to the process exit code."""
    statuses = {o.status for o in outcomes}
    if StageStatus.FAILED in statuses:
        return EXIT_FAILED
    if statuses & {StageStatus.INCOMPLETE, StageStatus.DEFERRED}:
        return EXIT_INCOMPLETE
    return EXIT_OK


def _prepare(cfg: DictConfig, run_dir: str | None) -> DictConfig:
    """Copy ``cfg`` and pin values that must not change while it runs (run dir, run name, device)."""
    cfg = copy.deepcopy(cfg)
    cfg.run_name = str(cfg.run_name)
    cfg.run_dir = str(Path(run_dir or cfg.run_dir).resolve())
    cfg.device = resolve_device(str(cfg.device))
    return cfg


def _invocation(cfg: DictConfig, git: dict[str, Any], full_hash: str) -> dict[str, Any]:
    """One entry of ``manifest.invocations``."""
    return {
        "started_at": datetime.now(UTC).isoformat(timespec="seconds"),
        "argv": sys.argv,
        "stages": list(cfg.stages),
        "seed": int(cfg.seed),
        "scale": str(cfg.scale.value if hasattr(cfg.scale, "value") else cfg.scale),
        "device": str(cfg.device),
        "config_hash": full_hash,
        **git,
    }


def _resume_hint(cfg: DictConfig, code: int) -> str:
    """What to type to continue this run, when there is something to continue."""
    if code == EXIT_OK:
        return ""
    return f"resume: rerun the same command with run_dir={cfg.run_dir} (finished stages are skipped)"


def run_pipeline(
    cfg: DictConfig, registry: Sequence[StageSpec] | None = None, run_dir: str | None = None
) -> dict[str, Any]:
    """Run the stages selected by ``cfg.stages`` in one run directory and return the summary.

    Args:
        cfg: composed pipeline config (``PipelineCfg``).
        registry: stages in order; defaults to ``stage_registry.STAGES`` (tests pass toy stages).
        run_dir: overrides ``cfg.run_dir`` (Hydra multirun passes each job's folder).

    Returns:
        The summary also written to ``<run_dir>/summary.json``, with ``exit_code``.

    Raises:
        PipelineConfigError: ``run_dir`` holds another experiment, or results of a changed stage that ``force``
            does not name (:func:`run_guard.run_dir_problem`); nothing is written then.
    """
    registry = tuple(registry if registry is not None else stage_registry.STAGES)
    validate_selection(cfg, registry)
    cfg = _prepare(cfg, run_dir)
    problem = run_dir_problem(cfg, registry)
    if problem is not None:
        raise PipelineConfigError(*problem)
    seed_everything(int(cfg.seed))
    layout = RunDir(Path(cfg.run_dir))
    container = OmegaConf.to_container(cfg, resolve=True, enum_to_str=True)
    assert isinstance(container, dict)
    resolved = {str(k): v for k, v in container.items()}
    atomic_write_yaml(layout.config_yaml, resolved)
    git = write_git_state(REPO_ROOT, layout.root)
    manifest = Manifest.load(layout.manifest_json)
    manifest.exp_name = str(cfg.exp_name)
    manifest.config_hash = config_hash(hashable_config(cfg, [s.name for s in registry]))
    manifest.invocations.append(_invocation(cfg, git, manifest.config_hash))
    manifest.save()
    log = job_log_path(layout.root)
    info = {**resolved, "git_commit": git["commit"], "scale": manifest.invocations[-1]["scale"], "log": log.name}
    print_header(info)
    with library_output_to(log, console):
        outcomes = _run_stages(cfg, registry, manifest, resolved)
    code = exit_code(outcomes)
    summary = {
        "exp_name": cfg.exp_name,
        "run_dir": cfg.run_dir,
        "scale": info["scale"],
        "device": cfg.device,
        "seed": int(cfg.seed),
        "config_hash": manifest.config_hash,
        "git_commit": git["commit"],
        "stages": [o.to_dict() for o in outcomes],
        "exit_code": code,
    }
    atomic_write_json(layout.summary_json, summary)
    hint = _resume_hint(cfg, code)
    atomic_write_text(layout.summary_md, summary_markdown(summary, registry, manifest, log.name, hint))
    print_ending(str(layout.summary_md), hint, [SMOKE_CONSOLE_NOTE] if info["scale"] == "smoke" else [])
    return summary


def _run_stages(
    cfg: DictConfig, registry: Sequence[StageSpec], manifest: Manifest, resolved: dict[str, Any]
) -> list[StageOutcome]:
    """Run every stage in order under a progress bar, logging metrics to the trackers."""
    deadline = None if cfg.max_minutes is None else time.monotonic() + 60.0 * float(cfg.max_minutes)
    runner = StageRunner(cfg, registry, manifest, stage_hashes(cfg, registry), len(manifest.invocations) - 1, deadline)
    tracker = Tracker(cfg.tracking, Path(cfg.run_dir), str(cfg.run_name), resolved)
    outcomes: list[StageOutcome] = []
    try:
        with stage_progress() as progress:
            task = progress.add_task("pipeline", total=len(registry), count=f"0/{len(registry)} stages")
            for step, spec in enumerate(registry):
                progress.update(task, description=spec.name)
                outcome = runner.run_stage(spec)
                outcomes.append(outcome)
                if outcome.status is StageStatus.DONE:
                    tracker.log_stage(step, spec.name, outcome.metrics, outcome.duration_s)
                if outcome.status is not StageStatus.DISABLED:
                    say(stage_line(outcome.to_dict(), headline(spec.name, outcome.metrics)))
                progress.update(task, advance=1, count=f"{step + 1}/{len(registry)} stages")
    finally:
        tracker.close()
    return outcomes


def run_from_hydra(cfg: DictConfig) -> int:
    """Task body for ``@hydra.main``: run the pipeline (each multirun job in its own folder), return the exit code."""
    from hydra.core.hydra_config import HydraConfig
    from hydra.types import RunMode

    run_dir = None
    if HydraConfig.initialized() and HydraConfig.get().mode == RunMode.MULTIRUN:
        run_dir = HydraConfig.get().runtime.output_dir
    return int(run_pipeline(cfg, run_dir=run_dir)["exit_code"])
