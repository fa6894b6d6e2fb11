# SPDX-License-Identifier: Apache-2.0
"""What the paper's tables still need, written as a task file for the GPU queue (issue 9).

Reads the runs behind the tables (``--run`` / ``--runs-file``, as ``gmloco.eval.report.paper_tables``) and lists, per
(policy, terrain, scenario) row:

* **reruns**: rows in which more than ``WINDOW_EXIT_NOTE_PCT`` % of the episodes had a sole leave its sand window
  early. The rerun takes the window that holds the row's recorded reach (``g1.window_report.covering_window`` of the reach
  that all but half that share of its walks stayed within: the rear or front grown where the soles passed it, a
  square where the robot turned out of it), one share per speed;
* **resumes**: run folders of rows short of ``--episodes`` (time boxes), each resumed under its own name (copy the
  folder to where the queue writes, ``.devsrc/row/`` for ``scripts/gpu/run_queue.sh``).

The task file holds one ``NAME g1_eval_cli-arguments`` line per task (``python -m gmloco.eval.g1.queue
--tasks FILE``), resumes first (they finish rows), then reruns, most exits first, each with a comment saying why. A
row can appear in both: the resume completes it at its window, the rerun replaces it. Exits within
``metrics.episodes.FALL_EXIT_S`` before a fall (a stumble's trailing sole) are not counted (``--fall-exits`` counts them):
the reach-window runs reran two rows made of such exits at a window no sole left and neither changed.

    python -m gmloco.eval.studies.tables_todo --runs-file results/mpm_eval/tables/runs.txt --out /tmp/todo_tasks.txt
"""

from __future__ import annotations

import argparse
import json
import math
import re
import shlex
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any

from gmloco.eval.g1.cli import cli_args
from gmloco.eval.g1.config import G1EvalCfg, episode_specs
from gmloco.eval.g1.score import reach_fits
from gmloco.eval.g1.window_report import WINDOW_TURN_SHARE, covering_window, reach_quantile
from gmloco.eval.metrics.episodes import FALL_EXIT_S, exit_in_fall, read_episodes
from gmloco.eval.metrics.locomotion import FailureCfg
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.window import SandWindowCfg
from gmloco.eval.report.paper_tables import WINDOW_EXIT_NOTE_PCT, _run_arg, runs_file

__all__ = ["Todo", "cfg_from_summary", "main", "todo"]


@dataclass
class Todo:
    """One task of the list: its queue line and why."""

    name: str
    """Task name = run folder name under the queue's output folder."""
    line: str
    """``NAME g1_eval_cli-arguments``."""
    why: str
    """What it completes."""
    resume_from: str | None = None
    """The run folder to copy beside the queue's output (resumes only)."""


def cfg_from_summary(cfg: dict[str, Any]) -> G1EvalCfg:
    """A run's ``G1EvalCfg`` from its ``summary.json`` ``cfg`` (unknown keys of older runs ignored).

    A window recorded without ``turn_with_robot`` (runs before the window turned with the robot) kept the grid's
    axes, and reads so.
    """

    def build(cls: type, d: dict[str, Any]) -> Any:
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in d.items() if k in names})

    top = {k: v for k, v in cfg.items() if k not in ("window", "solver", "failure")}
    out = build(G1EvalCfg, top)
    return replace(
        out,
        terrains=tuple(out.terrains),
        scenarios=tuple(out.scenarios),
        speeds=tuple(float(v) for v in out.speeds),
        window=build(SandWindowCfg, {"turn_with_robot": False} | cfg.get("window", {})),
        solver=build(MpmSolverCfg, cfg.get("solver", {})),
        failure=build(FailureCfg, cfg.get("failure", {})),
    )


def _line(name: str, cfg: G1EvalCfg) -> str:
    args = cli_args(replace(cfg, resume=True, max_minutes=None, device=None))
    if cfg.shards > 1:
        args += ["--shard", f"{cfg.shard}/{cfg.shards}"]
    return f"{name} {shlex.join(args)}"


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.]+", "_", text).strip("_")


def _row_key(label: str, r: dict[str, Any]) -> tuple[str, str, str]:
    return label, str(r["terrain"]), str(r["scenario"])


def todo(
    runs: list[tuple[str, Path]],
    episodes: int = 100,
    exit_pct: float = WINDOW_EXIT_NOTE_PCT,
    fall_exits: bool = False,
    notes: list[str] | None = None,
) -> list[Todo]:
    """The tasks that complete the tables of ``runs`` (label, run folder): resumes first, then window reruns.

    A row is rerun when more than ``exit_pct`` % of its episodes left the window early, not counting exits that
    came with the fall (``metrics.episodes.exit_in_fall``) unless ``fall_exits``; a row left out for that is said in
    ``notes``.

    Raises:
        FileNotFoundError: a run folder without ``summary.json`` or ``episodes.jsonl``.
    """
    cfgs: dict[Path, G1EvalCfg] = {}
    rows: dict[tuple[str, str, str], list[dict[str, Any]]] = {}
    folders: dict[tuple[str, str, str], list[Path]] = {}
    for label, d in runs:
        for need in ("summary.json", "episodes.jsonl"):
            if not (d / need).is_file():
                raise FileNotFoundError(f"{d}: no {need}; pass g1_eval output folders")
        cfgs[d] = cfg_from_summary(json.loads((d / "summary.json").read_text())["cfg"])
        for r in read_episodes(d / "episodes.jsonl"):
            key = _row_key(label, r)
            rows.setdefault(key, []).append(r)
            if d not in folders.setdefault(key, []):
                folders[key].append(d)
    resumes, reruns = [], []
    for key, rs in rows.items():
        label, terrain, scenario = key
        early = [r for r in rs if r.get("window_exit_early")]
        deciding = early if fall_exits else [r for r in early if not exit_in_fall(r)]
        if 100.0 * len(deciding) / len(rs) > exit_pct:
            reruns.append((len(early) / len(rs), _rerun(key, rs, early, cfgs[folders[key][0]], episodes, exit_pct)))
        elif 100.0 * len(early) / len(rs) > exit_pct and notes is not None:
            notes.append(f"{label}/{terrain}/{scenario}: not rerun: {len(early) - len(deciding)} of its "
                         f"{len(early)} early window exits came within {FALL_EXIT_S:g} s before the fall "
                         f"({len(deciding)} others, {100.0 * len(deciding) / len(rs):.0f} % of {len(rs)}; "
                         "--fall-exits lists it)")  # fmt: skip
        if len(rs) >= episodes:
            continue
        for d in folders[key]:
            cfg = cfgs[d]
            want = [s.key for s in episode_specs(cfg) if (s.terrain, s.scenario) == (terrain, scenario)]
            have = {r["key"] for r in rs}
            left = sum(k not in have for k in want)
            if left:
                why = f"{label}/{terrain}/{scenario}: {len(rs)} of {episodes}; {d.name} has {left} left"
                resumes.append(Todo(d.name, _line(d.name, cfg), why, str(d)))
    return resumes + [t for _, tasks in sorted(reruns, key=lambda x: -x[0]) for t in tasks]


def _turned(r: dict[str, Any], window: SandWindowCfg) -> bool:
    """Whether an early exit came from the robot's turn.

    Its recorded cause, or (runs before the per-terrain runs recorded none) soles that never reached past the window's extent
    along the heading.
    """
    if r.get("window_exit_cause") is not None:
        return r["window_exit_cause"] == "turn"
    reach = [float(v) for k in ("sole_behind_m", "sole_ahead_m", "sole_side_m") if (v := r.get(k)) is not None]
    if len(reach) < 3 or not all(math.isfinite(v) for v in reach):
        return True  # nothing known: a square holds a turn and the tables' reach alike
    return reach_fits((reach[0], reach[1], reach[2]), window)


def _rerun(
    key: tuple[str, str, str],
    rs: list[dict[str, Any]],
    early: list[dict[str, Any]],
    cfg: G1EvalCfg,
    episodes: int,
    exit_pct: float,
) -> list[Todo]:
    """One row again at the window holding its reach, one share per speed when the episodes split evenly."""
    label, terrain, scenario = key

    # at most half the exit threshold's share of the walks reaches beyond the rerun's window
    reach = tuple(0.0 if math.isnan(v) else v for v in reach_quantile(rs, 1.0 - exit_pct / 200.0))
    turned = sum(_turned(r, cfg.window) for r in early) >= WINDOW_TURN_SHARE * len(early)
    window = covering_window(reach, cfg.window, turned)  # type: ignore[arg-type]
    n = len(cfg.speeds) if episodes % len(cfg.speeds) == 0 else 1
    base = replace(cfg, terrains=(terrain,), scenarios=(scenario,), num_episodes=episodes, window=window, shards=n)  # type: ignore[arg-type]
    stem = _slug(f"{label}_{terrain}_{scenario}_w{window.length:g}x{window.width:g}")
    why = (f"{label}/{terrain}/{scenario}: {100.0 * len(early) / len(rs):.0f} % early window exits "
           f"({'turn' if turned else 'reach'}) at {cfg.window.length:g} x {cfg.window.width:g} m (lead "
           f"{cfg.window.lead:g}); rerun at {window.length:g} x {window.width:g} m (lead {window.lead:g})")  # fmt: skip
    names = [f"{stem}_share{i}of{n}" if n > 1 else stem for i in range(n)]
    return [Todo(nm, _line(nm, replace(base, shard=i)), why) for i, nm in enumerate(names)]


def main(argv: list[str] | None = None) -> list[Todo]:
    """Command line: write the task file and print what each task completes."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--run", type=_run_arg, action="append", default=[], help="LABEL=RUN_DIR (repeat)")
    p.add_argument("--runs-file", type=Path, default=None, help="a file of LABEL=RUN_DIR lines (globs allowed)")
    p.add_argument("--out", type=Path, required=True, help="the task file to write")
    p.add_argument("--episodes", type=int, default=100, help="episodes a complete row has (the paper: 100)")
    p.add_argument("--exit-pct", type=float, default=WINDOW_EXIT_NOTE_PCT,
                   help="rerun rows with more than this %% of early window exits")  # fmt: skip
    p.add_argument("--fall-exits", action="store_true",
                   help=f"count exits within {FALL_EXIT_S:g} s before a fall too (default: they came with the fall)")  # fmt: skip
    a = p.parse_args(argv)
    try:
        runs = list(a.run)
        runs += runs_file(a.runs_file) if a.runs_file is not None else []
        if not runs:
            p.error("give the runs: --run LABEL=RUN_DIR (repeat) and/or --runs-file FILE")
        notes: list[str] = []
        tasks = todo(runs, a.episodes, a.exit_pct, a.fall_exits, notes)
    except (FileNotFoundError, ValueError) as exc:
        p.error(str(exc))
    lines = ["# written by python -m gmloco.eval.studies.tables_todo: resumes first, then window reruns"]
    lines += [f"# {n}" for n in notes]
    for n in notes:
        print("skip   " + n)
    for t in tasks:
        lines += [f"# {t.why}" + (f" (resume: copy {t.resume_from})" if t.resume_from else ""), t.line]
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text("\n".join(lines) + "\n")
    for t in tasks:
        print(("resume " if t.resume_from else "rerun  ") + t.why)
    print(f"{len(tasks)} tasks -> {a.out}" if tasks else f"nothing left: the tables are complete -> {a.out}")
    return tasks


if __name__ == "__main__":
    main()
