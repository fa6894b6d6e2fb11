# SPDX-License-Identifier: Apache-2.0
"""Console output of the pipeline: a short header, one line per stage, progress bars inside stages, the ending.

Stages report through :func:`say` (a line above the bars) and :func:`stage_bar` (a bar of their own while they
run); both do nothing visible outside a running pipeline, so a stage function called from a test stays silent.
Library output never reaches this console: :mod:`run_log` sends it to the run's log file.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

from workflows.manifest import StageStatus

__all__ = [
    "STATUS_STYLE",
    "console",
    "print_ending",
    "print_header",
    "say",
    "stage_bar",
    "stage_line",
    "stage_progress",
]

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

_live: list[Progress] = []
"""The pipeline's progress display while stages run (empty otherwise)."""

Advance = Callable[..., None]
"""``update(completed, description=None)`` of one stage bar."""


def print_header(info: dict[str, Any]) -> None:
    """Announce what is about to run in two lines: experiment, scale, device, seed; run directory and commit."""
    console.print(
        f"[bold]gmloco[/] {info.get('exp_name')}: scale {info.get('scale')}, device {info.get('device')}, "
        f"seed {info.get('seed')}, commit {str(info.get('git_commit'))[:8]}",
        soft_wrap=True,
    )
    console.print(
        f"  run directory {escape(str(info.get('run_dir')))}; library output in {escape(info['log'])}", soft_wrap=True
    )


@contextmanager
def stage_progress() -> Iterator[Progress]:
    """Progress display over the pipeline's stages; bars vanish when done, the stage lines stay."""
    progress = Progress(
        SpinnerColumn(),
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("{task.fields[count]}"),
        TimeElapsedColumn(),
        console=console,
        transient=True,
        redirect_stdout=False,  # library prints go to the log file (run_log), never above the bars
        redirect_stderr=False,
    )
    with progress:
        _live.append(progress)
        try:
            yield progress
        finally:
            _live.remove(progress)


def say(text: str) -> None:
    """Print one line above the progress bars (plain console output outside a pipeline run); never wrapped."""
    (_live[-1].console if _live else console).print(text, soft_wrap=True)


@contextmanager
def stage_bar(description: str, total: float, unit: str) -> Iterator[Advance]:
    """A bar for the work inside a stage (iterations, episodes, fits); yields ``update(completed, description)``.

    Args:
        description: Label left of the bar.
        total: Amount of work (``unit`` s, or 1.0 for a fraction).
        unit: Shown after ``completed/total``; ``"%"`` shows a percentage of ``total``.
    """
    if not _live:
        yield lambda completed, description=None: None
        return
    progress = _live[-1]

    def count(done: float) -> str:
        return f"{100.0 * done / max(total, 1e-12):.0f}%" if unit == "%" else f"{done:g}/{total:g} {unit}"

    task = progress.add_task(f"  {description}", total=total, count=count(0))

    def update(completed: float, description: str | None = None) -> None:
        fields: dict[str, Any] = {"description": f"  {description}"} if description else {}
        progress.update(task, completed=completed, count=count(completed), **fields)

    try:
        yield update
    finally:
        progress.remove_task(task)


def _details(row: dict[str, Any]) -> str:
    """Message, or the first few metrics, of one summary row."""
    if row["message"] and row["status"] != StageStatus.SKIPPED.value:
        return row["message"]
    metrics = ", ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in row["metrics"].items())
    return "; ".join(x for x in (row["message"], metrics[:100]) if x)


def stage_line(row: dict[str, Any], headline: str) -> str:
    """One console line for a finished stage: name, status, time, then its headline numbers or its message."""
    style = STATUS_STYLE[StageStatus(row["status"])]
    status = f"[{style}]{row['status']:<8}[/]"
    if headline and row["status"] == StageStatus.DONE.value:
        detail = headline
    elif headline and row["status"] == StageStatus.SKIPPED.value:
        detail = f"{row['message']}: {headline}"
    else:
        detail = _details(row)
    return f"  {row['stage']:<14}{status} {row['duration_s']:7.1f} s  {escape(detail)}".rstrip()


def print_ending(summary_md: str, hint: str, notes: Sequence[str] = ()) -> None:
    """Point to ``summary.md``, print the notes (e.g. smoke scale) and how to resume, one line each."""
    for note in notes:
        console.print(f"[yellow]{escape(note)}[/]", soft_wrap=True)
    console.print(f"summary: {escape(summary_md)}", soft_wrap=True)
    if hint:
        console.print(escape(hint), soft_wrap=True)
