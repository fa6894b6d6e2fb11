# SPDX-License-Identifier: Apache-2.0
"""``summary.md``: what each stage of a run produced and its key numbers, for a reader rather than a program.

``summary.json`` beside it holds every metric; this file picks the few that say what a stage did
(:data:`HEADLINES`) and, at smoke scale, says plainly that the numbers check the machinery and mean nothing
about the policy.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from workflows.manifest import Manifest, StageStatus
from workflows.stage_registry import StageSpec

__all__ = ["HEADLINES", "SMOKE_CONSOLE_NOTE", "SMOKE_NOTE", "headline", "summary_markdown"]

SMOKE_NOTE = (
    "These are smoke-scale numbers: a few environments, two training iterations, one 1 s walk on a coarse sand "
    "grid and a short slice of the sample recording. They prove that every stage runs end to end; they are not "
    "meaningful about the policy (a success rate of 0 and a mismatch verdict of `unexplained` are expected here). "
    "Run `+scale=full` on a GPU for numbers worth reading."
)
"""The plain statement written into ``summary.md`` of a smoke-scale run."""
SMOKE_CONSOLE_NOTE = (
    "smoke scale: these numbers show that every stage runs; they are not meaningful about the policy "
    "(summary.md says why)."
)
"""Its one-line form on the console."""

_MAX_FILES = 12
"""Output files listed per stage in ``summary.md`` (the rest are counted)."""


def _num(value: Any, fmt: str = ".3g", unit: str = "") -> str:
    """Format a metric; missing or non-finite values read ``n/a``."""
    if not isinstance(value, int | float) or isinstance(value, bool) or not math.isfinite(value):
        return "n/a"
    return f"{value:{fmt}}{unit}"


def _megabytes(size: Any) -> Any:
    """A byte count in MB (anything else passes through, to read ``n/a``)."""
    return size / 1e6 if isinstance(size, int | float) else size


def _training(m: Mapping[str, Any]) -> list[tuple[str, str]]:
    """Key numbers of a training stage (teacher or student)."""
    return [
        ("iteration", _num(m.get("iteration"), ".0f")),
        ("mean reward", _num(m.get("mean_reward"))),
        ("mean episode length", _num(m.get("mean_episode_length"), ".0f", " steps")),
        ("time per iteration", _num(m.get("seconds_per_iteration"), ".2f", " s")),
    ]


def _export(m: Mapping[str, Any]) -> list[tuple[str, str]]:
    """Key numbers of the ONNX export check."""
    return [
        ("ONNX vs torch, max abs action difference", _num(m.get("onnx_max_abs_diff"), ".1e")),
        ("same over a rollout", _num(m.get("rollout_onnx_max_abs_diff"), ".1e")),
        ("ONNX size", _num(_megabytes(m.get("onnx_bytes")), ".2f", " MB")),
    ]


def _eval_mpm(m: Mapping[str, Any]) -> list[tuple[str, str]]:
    """Key numbers of the MPM evaluation (all cells pooled)."""
    lo, hi = _num(m.get("all/success_lo95"), ".0%"), _num(m.get("all/success_hi95"), ".0%")
    return [
        ("episodes", _num(m.get("all/num_episodes"), ".0f")),
        ("success rate (95% interval)", f"{_num(m.get('all/success_rate'), '.0%')} ({lo} to {hi})"),
        ("velocity tracking error", _num(m.get("all/vel_error"), ".2f", " m/s")),
        ("mean sinkage", _num(m.get("all/mean_sinkage"), ".3f", " m")),
    ]


def _analyze_logs(m: Mapping[str, Any]) -> list[tuple[str, str]]:
    """Key numbers of the robot-log analysis."""
    return [
        ("recordings read", _num(m.get("recordings"), ".0f")),
        ("figures", _num(m.get("figures"), ".0f")),
        ("mean tracking RMSE", _num(m.get("tracking_rmse_mean"), ".3f", " rad")),
    ]


def _mismatch(m: Mapping[str, Any]) -> list[tuple[str, str]]:
    """Key numbers of the mismatch discovery."""
    return [
        ("verdict", str(m.get("verdict", "n/a"))),
        ("winning effect", str(m.get("winner", "n/a"))),
        ("explained fraction", _num(m.get("explained_fraction"), ".0%")),
        ("recording analysed", _num(m.get("recording_s"), ".1f", " s")),
    ]


HEADLINES: dict[str, Callable[[Mapping[str, Any]], list[tuple[str, str]]]] = {
    "train_teacher": _training,
    "distill": _training,
    "export": _export,
    "eval_mpm": _eval_mpm,
    "analyze_logs": _analyze_logs,
    "mismatch": _mismatch,
}
"""Per stage: its key numbers as (label, formatted value)."""


def _first_metrics(m: Mapping[str, Any], count: int = 4) -> list[tuple[str, str]]:
    """The first few metrics of a stage without a headline rule."""
    return [(k, v if isinstance(v, str) else _num(v)) for k, v in list(m.items())[:count]]


def headline(stage: str, metrics: Mapping[str, Any]) -> str:
    """The key numbers of ``stage`` on one line (the console's stage line)."""
    pairs = (HEADLINES.get(stage, _first_metrics))(metrics) if metrics else []
    return ", ".join(f"{label} {value}" for label, value in pairs if value != "n/a")


def _files(outputs: Mapping[str, int]) -> list[str]:
    """Markdown list items of a stage's output files with sizes."""
    names = sorted(outputs)
    items = [f"- `{n}` ({outputs[n] / 1e3:.1f} kB)" for n in names[:_MAX_FILES]]
    if len(names) > _MAX_FILES:
        items.append(f"- ... and {len(names) - _MAX_FILES} more files")
    return items


def _stage_section(row: Mapping[str, Any], spec: StageSpec, manifest: Manifest) -> list[str]:
    """The ``## <stage>`` section of one summary row."""
    lines = [f"## {row['stage']}", "", f"{spec.summary}.", "", f"Status: **{row['status']}**"]
    if row["status"] in (StageStatus.DONE.value, StageStatus.SKIPPED.value):
        lines[-1] += f" in {row['duration_s']:.1f} s" if row["status"] == StageStatus.DONE.value else ""
        rec = manifest.stages.get(row["stage"])
        folder = rec.out_dir if rec is not None else row["stage"]
        pairs = (HEADLINES.get(row["stage"], _first_metrics))(row["metrics"]) if row["metrics"] else []
        if pairs:
            lines += ["", "| number | value |", "|---|---|", *(f"| {k} | {v} |" for k, v in pairs)]
        outputs = rec.outputs if rec is not None else {}
        lines += ["", f"Produced in `{folder}`:", "", *(_files(outputs) or ["- (no files)"])]
    elif row["message"]:
        lines[-1] += f": {row['message']}"
    return [*lines, ""]


def summary_markdown(
    summary: Mapping[str, Any], registry: Sequence[StageSpec], manifest: Manifest, log_name: str, hint: str
) -> str:
    """Return ``summary.md`` for a run's ``summary.json`` content.

    Args:
        summary: What :func:`pipeline_run.run_pipeline` returns (stages, scale, device, ...).
        registry: The stages, for their one-line descriptions.
        manifest: The run's manifest, for each stage's output files and folder.
        log_name: File name of the run's log (library output).
        hint: How to continue the run ('' when it is complete).
    """
    specs = {s.name: s for s in registry}
    lines = [
        f"# Run summary: {summary['exp_name']}",
        "",
        f"- scale: **{summary['scale']}**, device {summary['device']}, seed {summary['seed']}",
        f"- git commit {summary['git_commit']}, config hash {summary['config_hash']}",
        f"- run directory `{summary['run_dir']}`; library output in `{log_name}`; every metric in `summary.json`",
        "",
    ]
    if summary["scale"] == "smoke":
        lines += [f"> {SMOKE_NOTE}", ""]
    if hint:
        lines += [f"This run is not complete: {hint}.", ""]
    for row in summary["stages"]:
        if row["status"] != StageStatus.DISABLED.value:
            lines += _stage_section(row, specs[row["stage"]], manifest)
    disabled = [r["stage"] for r in summary["stages"] if r["status"] == StageStatus.DISABLED.value]
    if disabled:
        lines += [f"Not selected in `stages`: {', '.join(disabled)}.", ""]
    return "\n".join(lines)
