# SPDX-License-Identifier: Apache-2.0
"""Console output of the pipeline: the announcement panel, the stage progress bar and the summary table."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from rich.console import Console
from rich.progress import BarColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn
from rich.table import Table

from manifest import StageStatus

__all__ = ["STATUS_STYLE", "console", "print_header", "print_summary", "stage_progress"]

console = Console(stderr=True, highlight=False)
"""All human-facing output goes to stderr; stdout stays free for ``--cfg`` and scripting."""

STATUS_STYLE = {
    StageStatus.DONE: "green",
    StageStatus.SKIPPED: "cyan",
    StageStatus.NOT_IMPLEMENTED: "yellow",
    StageStatus.BLOCKED: "yellow",
    StageStatus.INCOMPLETE: "magenta",
    StageStatus.DEFERRED: "magenta",
    StageStatus.FAILED: "bold red",
    StageStatus.DISABLED: "dim",
}
"""Rich style per status."""


def print_header(info: dict[str, Any]) -> None:
    """Announce what is about to run (experiment, scale, device, seed, run directory)."""
    fields = ("exp_name", "scale", "device", "seed", "run_dir", "git_commit")
    console.rule("[bold]gmloco pipeline")
    for key in fields:
        console.print(f"  {key:<10} {info.get(key)}")


def stage_progress() -> Progress:
    """Progress bar over the pipeline's stages."""
    return Progress(
        SpinnerColumn(),
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} stages"),
        TimeElapsedColumn(),
        console=console,
    )


def _details(row: dict[str, Any]) -> str:
    """Message, or the first few metrics, of one summary row."""
    if row["message"] and row["status"] != StageStatus.SKIPPED.value:
        return row["message"]
    metrics = ", ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in row["metrics"].items())
    return "; ".join(x for x in (row["message"], metrics[:120]) if x)


def print_summary(rows: Sequence[dict[str, Any]], run_dir: str, hint: str) -> None:
    """Print the per-stage summary table and how to resume."""
    table = Table(title="pipeline summary", show_lines=False)
    for col in ("stage", "status", "time [s]", "outputs", "details"):
        table.add_column(col)
    for row in rows:
        style = STATUS_STYLE[StageStatus(row["status"])]
        table.add_row(
            row["stage"],
            f"[{style}]{row['status']}[/]",
            f"{row['duration_s']:.1f}",
            str(row["outputs"]),
            _details(row),
        )
    console.print(table)
    console.print(f"run directory: {run_dir}")
    if hint:
        console.print(hint)
