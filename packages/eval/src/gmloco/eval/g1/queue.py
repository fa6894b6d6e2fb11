# SPDX-License-Identifier: Apache-2.0
"""Several GPUs, one evaluation each: the MPM evaluation's cells spread over a machine's GPUs (issue 9).

One ``g1.cli`` process drives one GPU; running several on one GPU does not pay (the window-behind-pelvis runs: seven side by side
on an H100 summed ~112 robot-frames/s against ~150 for one alone). On a machine with N GPUs this tool splits the
evaluation into one task per (terrain, scenario) cell, each with its own run folder ``OUT/<terrain>__<scenario>``
(with ``--shards N``: N tasks per cell, ``OUT/<terrain>__<scenario>__share<I>ofN``, each scoring the episodes whose
index k has k % N == I, so a long row runs on N GPUs at once and its first row is done first),
and keeps every GPU busy from a shared queue (a GPU takes the next task when its last one ends). Each task is
time-boxed to what is left of ``--max-minutes`` and resumable like any evaluation run (same ``--out``); a task that
would get less than a minute is not started. Afterwards, combine the folders with ``gmloco.eval.report.paper_tables``
(the queue prints the command: the folders share one label, so they are pooled into one policy's rows).

    python -m gmloco.eval.g1.queue --gpus 0 1 2 3 --out results/mpm_eval/td
        --terrains basalt dry_sand poppy_seed --scenarios straight circle --max-minutes 25
        -- --policy artifacts/gm_loco_student_td/policy.onnx

``--check`` parses every task's arguments as ``g1.cli`` will and exits: run it on the CPU before spending
device time on a job. Everything after ``--`` goes to every ``g1.cli`` call (policy, window, numerics, episodes). Writes
``OUT/queue.json`` (per task: GPU, return code, start and minutes, log file; per row split into shares: its
wall-clock from the first share's start to the last one's end, ``row_spans``).

Rows of several policies, windows or checks in one queue: ``--tasks FILE`` instead of ``--terrains``, one task per
line, ``NAME g1_eval_cli-arguments...`` (shell quoting; blank lines and ``#`` comments skipped), run in file order,
each in ``OUT/NAME`` (an existing folder resumes):

    table_td_basalt_share0of4 --policy artifacts/gm_loco_student_td/policy.onnx --terrains basalt --shard 0/4
    table_ppo_rigid --policy artifacts/ppo_rigid/policy.onnx --terrains dry_sand --window-width 1.3
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shlex
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

__all__ = [
    "Launch",
    "QueueTask",
    "TaskResult",
    "cell_tasks",
    "check_tasks",
    "file_tasks",
    "main",
    "row_spans",
    "run_queue",
    "share_row",
]

MIN_TASK_MINUTES = 1.0
"""A task that would get less than this is not started [min] (it would only build its solver)."""


@dataclass(frozen=True)
class QueueTask:
    """One ``g1.cli`` call: a run folder name and its arguments (without ``--out`` and ``--max-minutes``)."""

    name: str
    argv: tuple[str, ...]


@dataclass
class TaskResult:
    """What became of a task."""

    name: str
    gpu: str | None = None
    """The GPU (``CUDA_VISIBLE_DEVICES`` value) it ran on; None if it was not started."""
    returncode: int | None = None
    started_min: float | None = None
    """When it started, in minutes after the queue started (None if it was not started)."""
    minutes: float = 0.0
    """How long it ran [min]."""
    log: str = ""


_QUEUE_FLAGS = ("--out", "--max-minutes", "--device")
"""``g1.cli`` arguments the queue sets per task."""


def cell_tasks(terrains: list[str], scenarios: list[str], argv: list[str], shards: int = 1) -> list[QueueTask]:
    """One task per (terrain, scenario), in that order (give the most wanted first).

    With ``shards`` > 1, that many per cell, each scoring one share of its episodes (``--shard I/N``), so several
    GPUs walk one row at once.

    Raises:
        ValueError: An argument the queue sets per task is among ``argv``, or ``shards`` < 1.
    """
    for flag in (*_QUEUE_FLAGS, "--terrains", "--scenarios", "--shard"):
        if flag in argv:
            raise ValueError(f"{flag} is set by the queue per task; remove it from the arguments after --")
    if shards < 1:
        raise ValueError(f"--shards {shards}: split each cell into at least 1 share")
    tasks = []
    for t in terrains:
        for s in scenarios:
            cell = (*argv, "--terrains", t, "--scenarios", s)
            if shards == 1:
                tasks.append(QueueTask(f"{t}__{s}", cell))
            else:
                tasks += [QueueTask(f"{t}__{s}__share{i}of{shards}", (*cell, "--shard", f"{i}/{shards}"))
                          for i in range(shards)]  # fmt: skip
    return tasks


def file_tasks(path: Path, argv: list[str]) -> list[QueueTask]:
    """The tasks of a task file (see the module docstring), each with ``argv`` appended; in file order.

    Raises:
        ValueError: The file is missing or holds no task, a name repeats or is not a plain folder name, or a line
            sets an argument the queue sets per task.
    """
    if not path.is_file():
        raise ValueError(f"--tasks {path}: no such file; write one task per line: NAME g1_eval_cli-arguments")
    tasks: list[QueueTask] = []
    for n, line in enumerate(path.read_text().splitlines(), start=1):
        words = shlex.split(line, comments=True)
        if not words:
            continue
        name, args = words[0], [*words[1:], *argv]
        where = f"--tasks {path}, line {n}"
        if not re.fullmatch(r"[A-Za-z0-9_.+=-]+", name):
            raise ValueError(f"{where}: the task name {name!r} must be a folder name (letters, digits, _ . + = -)")
        if any(t.name == name for t in tasks):
            raise ValueError(f"{where}: the task name {name!r} is used twice (each task has its own run folder)")
        if bad := [f for f in _QUEUE_FLAGS if f in args]:
            raise ValueError(f"{where}: {', '.join(bad)} is set by the queue per task; remove it")
        tasks.append(QueueTask(name, tuple(args)))
    if not tasks:
        raise ValueError(f"--tasks {path}: no task in it (one per line: NAME g1_eval_cli-arguments)")
    return tasks


Launch = Callable[[list[str], dict[str, str], Path], subprocess.Popen[bytes]]
"""Starts one task's command with its environment, output to its log file (tests pass a stand-in)."""


def _launch(cmd: list[str], env: dict[str, str], log: Path) -> subprocess.Popen[bytes]:
    """Start ``cmd`` with ``env``, its output appended to ``log``."""
    with log.open("ab") as f:
        return subprocess.Popen(cmd, env=env, stdout=f, stderr=subprocess.STDOUT)


def _command(task: QueueTask, out_root: Path, minutes: float | None) -> list[str]:
    cmd = [sys.executable, "-m", "gmloco.eval.g1.cli", *task.argv, "--out", str(out_root / task.name)]
    return cmd if minutes is None else [*cmd, "--max-minutes", f"{minutes:.2f}"]


def check_tasks(tasks: list[QueueTask]) -> None:
    """Parse every task's arguments as ``g1.cli`` will (before device time is spent on a typo).

    Raises:
        ValueError: A task's arguments do not parse; the message names the task and what ``g1.cli`` said.
    """
    import contextlib
    import io

    from gmloco.eval.g1.cli import _parse

    for t in tasks:
        err = io.StringIO()
        try:
            with contextlib.redirect_stderr(err):
                _parse([*t.argv, "--out", t.name])
        except SystemExit:
            said = err.getvalue().strip().splitlines()
            raise ValueError(f"task {t.name}: g1_eval_cli refuses its arguments: {said[-1] if said else ''}") from None


def run_queue(
    tasks: list[QueueTask],
    gpus: list[str],
    out_root: Path,
    max_minutes: float | None = None,
    launch: Launch = _launch,
    poll_s: float = 2.0,
) -> list[TaskResult]:
    """Run ``tasks`` over ``gpus``, one at a time per GPU, in order; return one result per task.

    Raises:
        ValueError: No GPU, or a GPU named twice.
    """
    if not gpus or len(set(gpus)) != len(gpus):
        raise ValueError(f"--gpus {gpus}: name each GPU once (CUDA_VISIBLE_DEVICES values, e.g. 0 1 2 3)")
    out_root.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    left = (lambda: None) if max_minutes is None else (lambda: max_minutes - (time.monotonic() - t0) / 60.0)
    results = {t.name: TaskResult(t.name, log=str(out_root / f"{t.name}.log")) for t in tasks}
    queue, running = list(tasks), {}  # gpu -> (task, process, start)
    while queue or running:
        for gpu in [g for g in gpus if g not in running]:
            minutes = left()
            if not queue or (minutes is not None and minutes < MIN_TASK_MINUTES):
                break
            task = queue.pop(0)
            env = {**os.environ, "CUDA_VISIBLE_DEVICES": gpu}
            running[gpu] = (task, launch(_command(task, out_root, minutes), env, out_root / f"{task.name}.log"),
                            time.monotonic())  # fmt: skip
            results[task.name].gpu = gpu
            results[task.name].started_min = round((time.monotonic() - t0) / 60.0, 2)
            print(f"[queue] {task.name} started on GPU {gpu}" + (f" ({minutes:.1f} min left)" if minutes else ""))
        if queue and not running:  # nothing runs and nothing may start: the time is up
            break
        for gpu, (task, proc, start) in list(running.items()):
            if (rc := proc.poll()) is not None:
                res = results[task.name]
                res.returncode, res.minutes = rc, round((time.monotonic() - start) / 60.0, 2)
                print(f"[queue] {task.name} on GPU {gpu}: rc={rc} after {res.minutes:.1f} min")
                del running[gpu]
        if running:
            time.sleep(poll_s)
    return [results[t.name] for t in tasks]


_SHARE = re.compile(r"^(?P<row>.+?)_{1,2}share(?P<i>\d+)of(?P<n>\d+)$")
"""A share's task name: ``ROW_shareIofN`` (task files) or ``CELL__shareIofN`` (``--shards``)."""


def share_row(name: str) -> str | None:
    """The row a share's task (or run folder) name belongs to: ``ROW`` of ``ROW_shareIofN`` / ``CELL__shareIofN``."""
    m = _SHARE.match(name)
    return None if m is None else m["row"]


def row_spans(results: list[TaskResult]) -> dict[str, dict[str, Any]]:
    """Wall-clock of each row split into shares, from its shares' start and end times.

    A row is listed once all its N shares started: ``wall_minutes`` runs from the first share's start to the last
    one's end (the time one row took on the machine), ``gpus`` the GPUs its shares ran on. Whether every share also
    finished all its episodes is in each run folder's ``summary.json`` (``complete``).
    """
    groups: dict[str, list[tuple[int, int, TaskResult]]] = {}
    for r in results:
        if (m := _SHARE.match(r.name)) is not None:
            groups.setdefault(m["row"], []).append((int(m["i"]), int(m["n"]), r))
    rows = {}
    for row, shares in groups.items():
        n = shares[0][1]
        started = [r for _, _, r in shares if r.started_min is not None]
        if {i for i, _, _ in shares} != set(range(n)) or len(started) != n:
            continue
        first = min(r.started_min for r in started if r.started_min is not None)
        last = max((r.started_min or 0.0) + r.minutes for r in started)
        rows[row] = {"shares": n, "gpus": sorted({r.gpu for r in started if r.gpu is not None}),
                     "wall_minutes": round(last - first, 2), "returncodes": [r.returncode for r in started]}  # fmt: skip
    return rows


def _policy_label(argv: list[str]) -> str:
    """The folder name of ``--policy`` among ``g1.cli`` arguments (``policy`` when none is given)."""
    if "--policy" not in argv or argv.index("--policy") + 1 >= len(argv):
        return "policy"
    return Path(argv[argv.index("--policy") + 1]).parent.name or "policy"


def main(argv: list[str] | None = None) -> list[TaskResult]:
    """Command line (see the module docstring)."""
    argv = sys.argv[1:] if argv is None else argv
    own, passthrough = (argv[: argv.index("--")], argv[argv.index("--") + 1 :]) if "--" in argv else (argv, [])
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--gpus", nargs="+", help="CUDA_VISIBLE_DEVICES values, one task at a time each (required to run)")
    p.add_argument("--out", type=Path, help="folder of the run folders, one per task (required to run)")
    p.add_argument("--terrains", nargs="+", help="one task per (terrain, scenario) cell")
    p.add_argument("--tasks", type=Path, help="task file instead of --terrains: one task per line (see above)")
    p.add_argument("--scenarios", nargs="+", default=["straight"])
    p.add_argument("--max-minutes", type=float, default=None, help="time box of the whole queue [min]")
    p.add_argument("--shards", type=int, default=1,
                   help="split each cell's episodes into this many tasks (e.g. the GPU count: one row on all GPUs)")  # fmt: skip
    p.add_argument("--label", default=None, help="policy label in the combined tables (default: the policy's folder)")
    p.add_argument("--check", action="store_true",
                   help="parse every task's arguments as g1_eval_cli does, print the tasks and exit (no GPU needed)")  # fmt: skip
    a = p.parse_args(own)
    if (a.terrains is None) == (a.tasks is None):
        p.error("give either --terrains (one task per cell) or --tasks FILE (one task per line)")
    if not a.check and (a.gpus is None or a.out is None):
        p.error("--gpus and --out are required to run the queue (only --check goes without them)")
    if a.tasks is not None and a.shards != 1:
        p.error("--shards splits --terrains cells; in a task file write the shares as lines with --shard I/N")
    try:
        if a.tasks is not None:
            tasks = file_tasks(a.tasks, passthrough)
        else:
            tasks = cell_tasks(a.terrains, a.scenarios, passthrough, a.shards)
        if a.check:
            check_tasks(tasks)
            print(f"{len(tasks)} tasks parse: {', '.join(t.name for t in tasks)}")
            return []
        results = run_queue(tasks, a.gpus, a.out, a.max_minutes)
    except ValueError as exc:
        p.error(str(exc))
    rows = row_spans(results)
    doc: dict[str, Any] = {"gpus": a.gpus, "max_minutes": a.max_minutes, "argv": passthrough,
                           "tasks": [asdict(r) for r in results], "rows": rows}  # fmt: skip
    (a.out / "queue.json").write_text(json.dumps(doc, indent=1) + "\n")
    for row, span in rows.items():
        print(f"[queue] row {row}: {span['shares']} shares on GPUs {' '.join(span['gpus'])}, "
              f"{span['wall_minutes']:.1f} min from the first share's start to the last one's end")  # fmt: skip
    failed = [r.name for r in results if r.returncode not in (0, None)]
    skipped = [r.name for r in results if r.gpu is None]
    if skipped:
        print(f"[queue] not started (time box): {', '.join(skipped)}; rerun the same command to go on")
    if failed:
        print(f"[queue] failed: {', '.join(failed)}; see their logs in {a.out}")
    argv_of = {t.name: list(t.argv) for t in tasks}
    runs = " ".join(f"--run {a.label or _policy_label(argv_of[r.name])}={a.out / r.name}"
                    for r in results if r.gpu is not None)  # fmt: skip
    print(f"[queue] combine: python -m gmloco.eval.report.paper_tables {runs} --out {a.out / 'tables'}"
          + (" (keep the table rows; leave out cost or check runs)" if a.tasks is not None else ""))  # fmt: skip
    return results


if __name__ == "__main__":
    main()
