# SPDX-License-Identifier: Apache-2.0
"""Contact-model ablation: the vanilla-PPO policies of each contact model, evaluated on one ground (``docs/sweeps.md``).

Usage::

    python workflows/ablation.py +ablation=contact_models                          # committed artifacts/<exp>/
    python workflows/ablation.py +ablation=contact_models ablation.source=train max_minutes=9   # train, then evaluate
    python workflows/ablation.py +ablation=contact_models run_dir=runs/ablation/<time>         # resume

For every experiment of ``ablation.exps`` (``ppo_rft3d``, ``ppo_heuristic_rft``, ``ppo_cone_multi``, ``ppo_rigid``)
the policy is either the committed ``artifacts/<exp>/policy.onnx`` (``source=artifacts``; an experiment without one
is reported **missing**, nothing is made up for it) or trained by the pipeline's train stage in
``<run_dir>/train/<exp>/`` (``source=train``; time-boxed and resumable like ``workflows/train.py``). Each policy is
rolled out by ``gmloco.train.evaluate_policy`` in the granular simulator with one contact model for all
(``ablation.eval_contact_model``, 3D-RFT by default) on every (material, speed) cell. Outputs in the run directory:
``config.yaml``, ``git/``, ``eval/<exp>.json`` (reused when the policy and settings are unchanged),
``ablation.md``, ``ablation.csv``, ``figures/ablation.png`` and ``summary.json``.

Exit codes: 0 every experiment evaluated or reported missing; 1 an evaluation or training failed; 2 bad input;
3 the time box was reached (rerun the same command with ``run_dir=`` to continue).
"""

from __future__ import annotations

import copy
import csv
import dataclasses
import hashlib
import io
import json
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf

if not __package__:  # run as ``python workflows/<name>.py``: the checkout root makes ``workflows`` importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workflows.pipeline_report import console
from workflows.pipeline_run import EXIT_FAILED, EXIT_INCOMPLETE, EXIT_OK, run_pipeline
from workflows.run_dir import (
    atomic_write_json,
    atomic_write_text,
    atomic_write_yaml,
    read_json,
    seed_everything,
    write_git_state,
)
from workflows.schemas import REPO_ROOT
from workflows.section_cfg import field_values, section_as
from workflows.stage_runner import PipelineConfigError, resolve_device

__all__ = ["Arm", "main", "markdown_table", "run_ablation", "table_rows"]

METRICS = ("success_rate", "vel_error", "yaw_rate_error", "num_envs")
"""Per-cell metrics of ``evaluate_policy`` in the table, in order."""
PASSED_THROUGH_SKIP = ("exp", "ablation", "run_dir", "run_name", "stages", "sweep", "hydra")
"""Command-line override keys not passed on to the experiments trained by ``source=train``."""


@dataclass
class Arm:
    """One experiment of the ablation."""

    exp: str
    """Experiment name (``conf/exp/<exp>.yaml``)."""
    status: str = "missing"
    """``evaluated``, ``missing``, ``incomplete`` (training stopped by its time box), ``failed`` or ``pending``."""
    reason: str = ""
    """Why it is missing, incomplete or failed."""
    policy: str | None = None
    """Path of the evaluated ``policy.onnx``."""
    sha256: str | None = None
    """SHA-256 of the policy file."""
    trained_on: str | None = None
    """Contact model the policy was trained with (ONNX metadata)."""
    iteration: float | None = None
    """Training iterations of the policy (its metrics.json), when known."""
    metrics: dict[str, float] = field(default_factory=dict)
    """``evaluate_policy`` metrics (``<material>/v<speed>/<metric>`` and ``all/<metric>``)."""


# Policies.


def _sha256(path: Path) -> str:
    """Hex SHA-256 of a file."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _iteration(folder: Path) -> float | None:
    """Training iteration recorded next to a policy (train's flat metrics.json or the runner's wrapped one)."""
    data = read_json(folder / "metrics.json", default={}) or {}
    value = data.get("iteration", (data.get("metrics") or {}).get("iteration"))
    return None if value is None else float(value)


def _found(arm: Arm, policy: Path) -> Arm:
    """Fill the policy's path, hash, training contact model and iteration."""
    import onnx

    meta = {p.key: p.value for p in onnx.load(str(policy), load_external_data=False).metadata_props}
    arm.status, arm.policy, arm.sha256 = "pending", str(policy), _sha256(policy)
    arm.trained_on, arm.iteration = meta.get("contact_model"), _iteration(policy.parent)
    return arm


def collect_artifact(cfg: DictConfig, exp: str) -> Arm:
    """The committed ``<artifacts_dir>/<exp>/policy.onnx``, or the experiment reported missing."""
    policy = Path(str(cfg.ablation.artifacts_dir)) / exp / "policy.onnx"
    if not policy.is_file():
        return Arm(exp, "missing", f"no committed policy: {policy} does not exist")
    return _found(Arm(exp), policy)


def _compose_arm(exp: str, overrides: Sequence[str]) -> DictConfig:
    """Compose ``+exp=<exp>`` with the ablation's other overrides (inside ``@hydra.main`` or not)."""
    from hydra.core.global_hydra import GlobalHydra

    args = [f"+exp={exp}", *overrides]
    if GlobalHydra.instance().is_initialized():
        from hydra import compose

        return compose("full_pipeline", overrides=args)
    from workflows.hydra_entry import compose_checked

    return compose_checked("full_pipeline", args)


def train_arm(exp: str, root: Path, overrides: Sequence[str], deadline: float | None) -> Arm:
    """Train (or resume) the experiment's train stage in ``<root>/train/<exp>`` through the pipeline."""
    cfg = _compose_arm(exp, overrides)
    if cfg.train_teacher.algorithm.value != "ppo":
        return Arm(exp, "failed", f"{exp} trains {cfg.train_teacher.algorithm.value}, not vanilla PPO (no policy.onnx)")
    cfg.stages = ["train_teacher"]
    if deadline is not None:
        cfg.max_minutes = max(0.0, (deadline - time.monotonic()) / 60.0)
    run_dir = root / "train" / exp
    row = run_pipeline(cfg, run_dir=str(run_dir))["stages"][0]
    if row["status"] in ("incomplete", "deferred"):
        return Arm(exp, "incomplete", f"training {row['status']}: {row['message']}")
    if row["status"] not in ("done", "skipped"):
        return Arm(exp, "failed", f"training {row['status']}: {row['message']}")
    return _found(Arm(exp), run_dir / "train_teacher" / "policy.onnx")


# Evaluation.


def eval_cells(cfg: DictConfig) -> Any:
    """The ``MaterialCellsCfg`` every policy is scored on (smoke scale: the ``smoke_*`` sizes)."""
    from gmloco.train.evaluation_cells import MaterialCellsCfg

    ab = cfg.ablation
    smoke = str(getattr(cfg.scale, "value", cfg.scale)) == "smoke"
    sizes = {"repeats": int(ab.smoke_repeats), "duration_s": float(ab.smoke_duration_s)} if smoke else {}
    return section_as(MaterialCellsCfg, ab, **sizes)


def eval_settings(cfg: DictConfig) -> dict[str, Any]:
    """What ``evaluate_policy`` is given besides the policy, as JSON values (smoke scale shortens it)."""
    ab = cfg.ablation
    model = ab.eval_contact_model
    cells = json.loads(json.dumps(dataclasses.asdict(eval_cells(cfg))))
    return {
        "contact_model": None if model is None else str(getattr(model, "value", model)),
        "terrain": str(getattr(ab.terrain, "value", ab.terrain)),
        **cells,
        "seed": int(cfg.seed),
    }


def evaluate_arm(cfg: DictConfig, arm: Arm, root: Path) -> Arm:
    """Evaluate the arm's policy, or reuse ``eval/<exp>.json`` written for the same policy and settings."""
    from workflows.policy_training import torch_device

    settings = eval_settings(cfg)
    out = root / "eval" / f"{arm.exp}.json"
    cached = read_json(out)
    if cached and cached.get("sha256") == arm.sha256 and cached.get("settings") == settings:
        arm.status, arm.metrics = "evaluated", cached["metrics"]
        return arm
    from gmloco.train import EvalCfg, evaluate_policy

    assert arm.policy is not None
    metrics = evaluate_policy(
        EvalCfg(
            **field_values(eval_cells(cfg)),
            policy_path=arm.policy,
            contact_model=settings["contact_model"],
            terrain=settings["terrain"],
            seed=settings["seed"],
            device=torch_device(str(cfg.device)),
        )
    )
    atomic_write_json(out, {"policy": arm.policy, "sha256": arm.sha256, "settings": settings, "metrics": metrics})
    arm.status, arm.metrics = "evaluated", metrics
    return arm


# Report.


def _cells(settings: dict[str, Any]) -> list[str]:
    """``<material>/v<speed>`` cell keys in evaluation order, then ``all``."""
    return [f"{m}/v{s:g}" for m in settings["materials"] for s in settings["speeds"]] + ["all"]


def table_rows(arms: Sequence[Arm], settings: dict[str, Any]) -> list[dict[str, Any]]:
    """One row per (experiment, cell) for evaluated arms; one row per experiment otherwise (metrics empty)."""
    rows = []
    for arm in arms:
        base = {"exp": arm.exp, "trained_on": arm.trained_on, "iteration": arm.iteration, "status": arm.status}
        if arm.status != "evaluated":
            rows.append({**base, "cell": "", **dict.fromkeys(METRICS), "note": arm.reason})
            continue
        for cell in _cells(settings):
            rows.append({**base, "cell": cell, **{m: arm.metrics.get(f"{cell}/{m}") for m in METRICS}, "note": ""})
    return rows


def _fmt(value: Any) -> str:
    """Table cell text: 3 significant digits for floats, '-' for None."""
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.3g}"
    return str(value)


def markdown_table(rows: Sequence[dict[str, Any]], settings: dict[str, Any], header: dict[str, Any]) -> str:
    """The comparison as markdown: settings, one table, the reasons of missing / failed experiments."""
    cols = ["exp", "trained_on", "iteration", "status", "cell", *METRICS]
    lines = [
        "# Contact-model ablation (vanilla PPO)",
        "",
        f"Evaluated with `gmloco.train.evaluate_policy` in the granular simulator, contact model "
        f"`{settings['contact_model'] or 'each policy own'}`, terrain `{settings['terrain']}`, "
        f"{settings['repeats']} env(s) per cell, {settings['duration_s']:g} s episodes, seed {settings['seed']}. "
        f"success_rate: fraction of envs that neither fell (base < 0.2 m) nor tilted (> π/4); vel_error [m/s] and "
        f"yaw_rate_error [rad/s]: mean tracking errors over the alive steps. Scale `{header['scale']}`, "
        f"commit `{header['git_commit']}`.",
        "",
        "| " + " | ".join(cols) + " |",
        "|" + "---|" * len(cols),
    ]
    lines += ["| " + " | ".join(_fmt(r[c]) for c in cols) + " |" for r in rows]
    notes = [f"- **{r['exp']}** {r['status']}: {r['note']}" for r in rows if r["note"]]
    return "\n".join([*lines, "", *notes, ""]) if notes else "\n".join([*lines, ""])


def _csv(rows: Sequence[dict[str, Any]]) -> str:
    """The rows as CSV."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=["exp", "trained_on", "iteration", "status", "cell", *METRICS, "note"])
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()


def _figure(path: Path, arms: Sequence[Arm], settings: dict[str, Any]) -> None:
    """Grouped bars per cell: success rate and velocity error of each evaluated experiment; missing ones named."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    cells = _cells(settings)
    done = [a for a in arms if a.status == "evaluated"]
    absent = [f"{a.exp} ({a.status})" for a in arms if a.status != "evaluated"]
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.2))
    x, width = np.arange(len(cells)), 0.8 / max(1, len(done))
    for ax, metric, label in zip(
        axes, ("success_rate", "vel_error"), ("success rate", "velocity error [m/s]"), strict=True
    ):
        for k, arm in enumerate(done):
            values = [arm.metrics.get(f"{c}/{metric}", np.nan) for c in cells]
            ax.bar(x + (k - (len(done) - 1) / 2) * width, values, width, label=arm.exp)
        ax.set_xticks(x, cells, rotation=20, ha="right", fontsize=8)
        ax.set(ylabel=label, title=label)
        if done:
            ax.legend(fontsize=8)
    model = settings["contact_model"] or "own"
    extra = f"; not evaluated: {', '.join(absent)}" if absent else ""
    fig.suptitle(f"vanilla PPO by training contact model, evaluated on {model} sand{extra}", fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _figure_or_note(path: Path, arms: Sequence[Arm], settings: dict[str, Any]) -> str:
    """Draw the figure and return its name, or say why not (the GPU image may lack matplotlib)."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return "not drawn: matplotlib is not installed; rerun the same command where it is (evaluations are reused)"
    _figure(path, arms, settings)
    return path.name


def write_report(arms: Sequence[Arm], cfg: DictConfig, root: Path, git: dict[str, Any], code: int) -> dict:
    """Write ``ablation.md``, ``ablation.csv``, ``figures/ablation.png`` and ``summary.json``; return the summary."""
    settings = eval_settings(cfg)
    header = {"scale": str(getattr(cfg.scale, "value", cfg.scale)), "git_commit": git["commit"]}
    rows = table_rows(arms, settings)
    atomic_write_text(root / "ablation.md", markdown_table(rows, settings, header))
    atomic_write_text(root / "ablation.csv", _csv(rows))
    summary = {
        "figure": _figure_or_note(root / "figures" / "ablation.png", arms, settings),
        "source": str(getattr(cfg.ablation.source, "value", cfg.ablation.source)),
        "settings": settings,
        **header,
        "device": str(cfg.device),
        "arms": [arm.__dict__ for arm in arms],
        "exit_code": code,
    }
    atomic_write_json(root / "summary.json", summary)
    return summary


# The workflow.


def _passed_overrides() -> list[str]:
    """The command line's overrides that also apply to the trained experiments (scale, device, sizes, ...)."""
    from hydra.core.hydra_config import HydraConfig

    if not HydraConfig.initialized():
        return []
    task = list(HydraConfig.get().overrides.task)
    return [o for o in task if o.lstrip("+~").split("=", 1)[0].split(".", 1)[0] not in PASSED_THROUGH_SKIP]


def _prepare(cfg: DictConfig) -> DictConfig:
    """Copy ``cfg``, pin run dir and device, check the ablation's input."""
    if cfg.get("ablation") is None:
        from workflows.config_errors import group_options

        choices = ", ".join(group_options("ablation"))
        raise PipelineConfigError("ablation", f"ablation: no ablation chosen: add +ablation=<name>. Valid: {choices}.")
    from workflows.config_errors import group_options

    unknown = [e for e in cfg.ablation.exps if e not in group_options("exp")]
    if unknown:
        valid = ", ".join(group_options("exp"))
        raise PipelineConfigError("ablation.exps", f"ablation.exps: unknown experiment(s) {unknown}; valid: {valid}.")
    cfg = copy.deepcopy(cfg)
    cfg.run_name, cfg.run_dir = str(cfg.run_name), str(Path(cfg.run_dir).resolve())
    cfg.device = resolve_device(str(cfg.device))
    return cfg


def _arm(cfg: DictConfig, exp: str, root: Path, overrides: Sequence[str], deadline: float | None) -> Arm:
    """Collect or train one experiment's policy and evaluate it; errors become a ``failed`` arm."""
    try:
        if str(getattr(cfg.ablation.source, "value", cfg.ablation.source)) == "train":
            arm = train_arm(exp, root, overrides, deadline)
        else:
            arm = collect_artifact(cfg, exp)
        return evaluate_arm(cfg, arm, root) if arm.status == "pending" else arm
    except Exception as e:  # one experiment's error must not hide the others' results
        return Arm(exp, "failed", f"{type(e).__name__}: {e}")


def run_ablation(cfg: DictConfig, arm_overrides: Sequence[str] | None = None) -> dict[str, Any]:
    """Collect or train each experiment's policy, evaluate it and write the comparison.

    Args:
        cfg: composed pipeline config with an ``ablation`` section.
        arm_overrides: overrides for the experiments trained by ``source=train`` (default: the command line's).

    Returns:
        The summary also written to ``<run_dir>/summary.json``, with ``exit_code``.
    """
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    cfg = _prepare(cfg)
    seed_everything(int(cfg.seed))
    root = Path(cfg.run_dir)
    atomic_write_yaml(root / "config.yaml", OmegaConf.to_container(cfg, resolve=True, enum_to_str=True))
    git = write_git_state(REPO_ROOT, root)
    overrides = list(arm_overrides) if arm_overrides is not None else _passed_overrides()
    deadline = None if cfg.max_minutes is None else time.monotonic() + 60.0 * float(cfg.max_minutes)
    arms: list[Arm] = []
    columns = (TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=console) as progress:
        bar = progress.add_task("ablation", total=len(cfg.ablation.exps))
        for exp in map(str, cfg.ablation.exps):
            if deadline is not None and time.monotonic() >= deadline:
                arms.append(Arm(exp, "incomplete", "time box reached before this experiment; rerun to continue"))
                continue
            progress.update(bar, description=f"ablation: {exp}")
            arms.append(_arm(cfg, exp, root, overrides, deadline))
            progress.console.print(f"  {exp}: {arms[-1].status} {arms[-1].reason}".rstrip())
            progress.advance(bar)
    statuses = {a.status for a in arms}
    code = EXIT_FAILED if "failed" in statuses else EXIT_INCOMPLETE if "incomplete" in statuses else EXIT_OK
    summary = write_report(arms, cfg, root, git, code)
    console.print((root / "ablation.md").read_text(encoding="utf-8"), markup=False)
    console.print(f"ablation written to {root} (ablation.md, ablation.csv, figures/ablation.png, summary.json)")
    return summary


def _defaults(argv: Sequence[str]) -> list[str]:
    """Add ``+exp=<first of ablation.exps>`` and ``run_dir=<runs>/ablation/<time>`` when the command line has none."""
    args = list(argv)
    if not any(a.lstrip("+").startswith("exp=") for a in args):
        from workflows.config_errors import CONF_DIR
        from workflows.schemas import AblationCfg

        names = [a.split("=", 1)[1] for a in args if a.lstrip("+").startswith("ablation=")]
        path = CONF_DIR / "ablation" / f"{names[0]}.yaml" if names else None
        loaded = OmegaConf.load(path) if path is not None and path.is_file() else None
        exps = loaded.get("exps") if isinstance(loaded, DictConfig) else None
        args.insert(0, f"+exp={(exps or AblationCfg().exps)[0]}")
    if not any(a.startswith(("run_dir=", "run_name=")) for a in args):
        args.insert(0, "run_dir=${paths.runs_dir}/ablation/${run_name}")
    return args


def _task(cfg: DictConfig) -> int:
    """Hydra task body: run the ablation, return its exit code."""
    return int(run_ablation(cfg)["exit_code"])


def main() -> None:
    """Command-line entry (Hydra)."""
    from workflows.hydra_entry import hydra_entry

    sys.argv = [sys.argv[0], *_defaults(sys.argv[1:])]
    hydra_entry(_task, only_stage="train_teacher")


if __name__ == "__main__":
    main()
