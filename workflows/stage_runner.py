# SPDX-License-Identifier: Apache-2.0
"""Run the selected stages in order inside one run directory: skip what is done, record what happens.

For every stage the runner decides one :class:`StageStatus`, writes ``<stage>/metrics.json`` for finished
stages and rewrites ``manifest.json`` atomically after each stage, so a kill at any point loses at most the
stage that was running.
"""

from __future__ import annotations

import copy
import time
import traceback
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf

from workflows.manifest import Manifest, StageRecord, StageStatus
from workflows.run_dir import atomic_write_json, list_outputs
from workflows.stage_registry import (
    StageIncompleteError,
    StageNotImplementedError,
    StageSpec,
    issue_text,
    load_stage_fn,
)

__all__ = ["PipelineConfigError", "StageOutcome", "StageRunner", "forced_stages", "validate_selection"]


class PipelineConfigError(ValueError):
    """A config value the pipeline cannot use; ``key`` names it for the error message."""

    def __init__(self, key: str, message: str) -> None:
        """Store the offending key next to the message."""
        self.key = key
        super().__init__(message)


def _names(registry: Sequence[StageSpec]) -> list[str]:
    """Stage names of ``registry`` in order."""
    return [s.name for s in registry]


def forced_stages(force: Any, registry: Sequence[StageSpec]) -> set[str]:
    """Interpret ``force``: ``true`` = all stages, ``false``/None = none, a name or list = those stages."""
    if force is None or force is False:
        return set()
    if force is True:
        return set(_names(registry))
    items = [force] if isinstance(force, str) else list(force)
    unknown = [str(i) for i in items if i not in _names(registry)]
    if unknown:
        valid = ", ".join(_names(registry))
        raise PipelineConfigError("force", f"unknown stage(s) {unknown} in 'force'; valid: true, false, {valid}.")
    return {str(i) for i in items}


def validate_selection(cfg: DictConfig, registry: Sequence[StageSpec]) -> None:
    """Raise :class:`PipelineConfigError` when ``stages`` or ``force`` names an unknown stage."""
    unknown = [s for s in cfg.stages if s not in _names(registry)]
    if unknown:
        valid = ", ".join(_names(registry))
        raise PipelineConfigError("stages", f"unknown stage(s) {unknown} in 'stages'; valid: {valid}.")
    forced_stages(OmegaConf.to_object(cfg.force) if OmegaConf.is_config(cfg.force) else cfg.force, registry)


def resolve_device(device: str) -> str:
    """Map ``auto`` to ``cuda`` when torch sees a GPU, else ``cpu``; other values pass through."""
    if device != "auto":
        return device
    try:
        import torch
    except ImportError:
        return "cpu"
    return "cuda" if torch.cuda.is_available() else "cpu"


@dataclass
class StageOutcome:
    """What happened to one stage in this invocation (a row of the summary table)."""

    name: str
    """Stage name."""
    status: StageStatus
    """Outcome."""
    message: str = ""
    """Reason or error."""
    issues: tuple[int, ...] = ()
    """Issues that implement the stage."""
    duration_s: float = 0.0
    """Wall time in this invocation [s]."""
    metrics: dict[str, Any] = field(default_factory=dict)
    """Metrics (this invocation's, or the reused ones for a skipped stage)."""
    outputs: int = 0
    """Number of output files."""

    def to_dict(self) -> dict[str, Any]:
        """Return a JSON-ready dict."""
        return {
            "stage": self.name,
            "status": self.status.value,
            "message": self.message,
            "issues": list(self.issues),
            "duration_s": round(self.duration_s, 3),
            "metrics": self.metrics,
            "outputs": self.outputs,
        }


def _now() -> str:
    """Current UTC time, ISO-8601."""
    return datetime.now(UTC).isoformat(timespec="seconds")


class StageRunner:
    """Decide, run and record the stages of one invocation."""

    def __init__(
        self,
        cfg: DictConfig,
        registry: Sequence[StageSpec],
        manifest: Manifest,
        hashes: Mapping[str, str],
        invocation: int,
        deadline: float | None,
    ) -> None:
        """Bind the run's config, registry, manifest, per-stage hashes and the invocation's deadline."""
        self.cfg = cfg
        self.registry = list(registry)
        self.manifest = manifest
        self.hashes = dict(hashes)
        self.invocation = invocation
        self.deadline = deadline
        self.forced = forced_stages(self._force_value(), registry)

    def _force_value(self) -> Any:
        """``cfg.force`` as a plain Python value."""
        force = self.cfg.force
        return OmegaConf.to_object(force) if OmegaConf.is_config(force) else force

    def run_stage(self, spec: StageSpec) -> StageOutcome:
        """Run or skip one stage and update the manifest; never raises for a stage's own error."""
        name, h = spec.name, self.hashes[spec.name]
        if name not in self.cfg.stages:
            return StageOutcome(name, StageStatus.DISABLED, "not in 'stages'", spec.issues)
        if name not in self.forced and self._satisfied(name):
            rec = self.manifest.stages[name]
            msg = f"already done for config {h}"
            return StageOutcome(name, StageStatus.SKIPPED, msg, spec.issues, 0.0, rec.metrics, len(rec.outputs))
        outcome = self._attempt(spec, h)
        self.manifest.save()
        return outcome

    def _attempt(self, spec: StageSpec, h: str) -> StageOutcome:
        """Decide whether the stage can run now and run it."""
        try:
            fn = load_stage_fn(spec)
        except Exception as e:  # an import error in a stage must not stop the others
            return self._record(spec, h, StageStatus.FAILED, f"import failed: {e!r}", 0.0, {})
        if getattr(fn, "gmloco_not_implemented", None):
            msg = f"not implemented yet ({issue_text(spec.issues)})"
            return self._record(spec, h, StageStatus.NOT_IMPLEMENTED, msg, 0.0, {})
        missing = [u for u in spec.needs if not self._satisfied(u)]
        if missing:
            why = ", ".join(f"{u} ({self._status_of(u)})" for u in missing)
            return self._record(spec, h, StageStatus.BLOCKED, f"needs {why}", 0.0, {})
        remaining = None if self.deadline is None else self.deadline - time.monotonic()
        if remaining is not None and remaining <= 0:
            return self._record(spec, h, StageStatus.DEFERRED, "pipeline time box used up; rerun to continue", 0, {})
        return self._execute(spec, h, fn, remaining)

    def _satisfied(self, name: str) -> bool:
        """Whether ``name`` is done for its current hash with intact outputs in its current folder."""
        return self.manifest.is_satisfied(name, self.hashes[name], str(self.cfg[name].out_dir))

    def _status_of(self, name: str) -> str:
        """Latest recorded status of ``name`` (or 'never run')."""
        rec = self.manifest.stages.get(name)
        if rec is None:
            return "never run"
        return rec.status.value if rec.config_hash == self.hashes[name] else "done for another config"

    def _resumable(self, name: str) -> bool:
        """Whether the stage may continue from its saved state: not forced, and not recorded for another config."""
        rec = self.manifest.stages.get(name)
        return name not in self.forced and (rec is None or rec.config_hash == self.hashes[name])

    def _stage_cfg(self, name: str, remaining_s: float | None) -> DictConfig:
        """Copy of the config with the stage's time box capped by the pipeline's and ``resume`` decided."""
        cfg = copy.deepcopy(self.cfg)
        cfg[name].resume = self._resumable(name)
        own = cfg[name].max_minutes
        if remaining_s is not None:
            cap = remaining_s / 60.0
            cfg[name].max_minutes = cap if own is None else min(float(own), cap)
        return cfg

    def _execute(self, spec: StageSpec, h: str, fn: Any, remaining_s: float | None) -> StageOutcome:
        """Call ``run(cfg)`` and translate its result or exception into a status."""
        out_dir = Path(self.cfg[spec.name].out_dir)
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / "error.log").unlink(missing_ok=True)
        started, t0 = _now(), time.monotonic()
        try:
            metrics = dict(fn(self._stage_cfg(spec.name, remaining_s)) or {})
        except StageNotImplementedError as e:
            _remove_if_empty(out_dir)
            return self._record(spec, h, StageStatus.NOT_IMPLEMENTED, str(e), time.monotonic() - t0, {}, started)
        except StageIncompleteError as e:
            msg = f"{e}; rerun the same command to continue"
            return self._record(spec, h, StageStatus.INCOMPLETE, msg, time.monotonic() - t0, {}, started)
        except Exception as e:  # record and continue with independent stages
            (out_dir / "error.log").write_text(traceback.format_exc(), encoding="utf-8")
            msg = f"{type(e).__name__}: {e} (traceback: {spec.name}/error.log)"
            return self._record(spec, h, StageStatus.FAILED, msg, time.monotonic() - t0, {}, started)
        duration = time.monotonic() - t0
        atomic_write_json(out_dir / "metrics.json", {"metrics": metrics, "config_hash": h, "finished_at": _now()})
        return self._record(spec, h, StageStatus.DONE, "", duration, metrics, started)

    def _record(
        self,
        spec: StageSpec,
        h: str,
        status: StageStatus,
        message: str,
        duration_s: float,
        metrics: dict[str, Any],
        started: str = "",
    ) -> StageOutcome:
        """Store the stage's record in the manifest (outputs listed for DONE) and return its outcome."""
        out_dir = str(self.cfg[spec.name].out_dir)
        outputs = list_outputs(out_dir) if status is StageStatus.DONE else {}
        self.manifest.stages[spec.name] = StageRecord(
            status, h, message, outputs, out_dir, metrics, started or _now(), round(duration_s, 3), self.invocation
        )
        return StageOutcome(spec.name, status, message, spec.issues, duration_s, metrics, len(outputs))


def _remove_if_empty(folder: Path) -> None:
    """Delete ``folder`` if the stage left nothing in it."""
    if folder.is_dir() and not any(folder.iterdir()):
        folder.rmdir()
