# SPDX-License-Identifier: Apache-2.0
"""Episodes of the G1 on MPM sand and their paper metrics (issue 9): batched, resumable, time-boxed, CPU or CUDA.

The episodes of one (terrain, scenario) cell run in ``robots_per_batch`` lanes of one MPM solver, each robot on
its own sand window (:mod:`gmloco.eval.mpm.window`; moving with the robot, or a static bed covering the course).
A lane whose robot fell or whose episode ended starts the cell's next episode at once (``refill``: start pose,
fresh sand), so a failing policy's episodes cost only the time they last (``run_cell``). An episode = the robot dropped onto fresh sand in its default pose, a constant command
for ``episode_s``: ``straight`` (v, 0, 0) or ``circle`` (v, 0, v / R). Logged at the policy rate (50 Hz) and scored
with :mod:`gmloco.eval.metrics.locomotion`:

* failure: base height < 0.2 m above the local sand surface, |roll| or |pitch| > pi/4, or the course not finished
  in ``episode_s``. The course is the commanded path (``circular_path``); it counts as finished once the nearest
  commanded sample to the base (searched forwards only) is past ``1 - course_slack`` of the path (a project
  choice: the paper gives no tolerance, and an exact v T lets no lag through).
* velocity tracking error: mean |v_xy - v_cmd| in the yaw frame over alive steps; heading error (the paper's yaw
  tracking error, ``heading_error_deg``): mean |wrap(psi - psi_cmd)| in degrees over alive steps, psi_cmd the start
  heading plus the commanded w_z integrated; yaw-rate error (``yaw_error``, an extra column): mean |w_z - w_cmd|
  [rad/s]; path error: DTW between executed and commanded xy paths (alive part).
* swing clearance: mean apex of the completed swings above the local surface and their lift above the stance
  before (``swing_clearance``: a foot is in swing while its sand force is below 40 N).
* window size needed: ``sole_behind_m`` / ``sole_ahead_m`` / ``sole_side_m``, the soles' largest reach from the
  pelvis (its yaw frame) while a corner is within 2 cm of the surface; summaries give their means per group.
* window check: ``window_exit_s``, the first time a sole corner within 2 cm of the surface lay outside its robot's
  sand window (no particles there), and ``window_exit_early`` when that was more than ``WINDOW_EXIT_GRACE_S`` before
  the episode ended; its rate is in the summary and the terrain table, and a run warns about it.
  ``window_exit_cause`` says why: ``"turn"`` when the soles were within the window's extent along the robot's
  heading (a window that does not turn, ``turn_with_robot=False``, was left behind by the robot's turn;
  ``window_exit_turn`` flags such early exits), ``"reach"`` when they stepped beyond it; ``heading_turn_deg`` is the
  heading's largest turn from its start. The default window turns with the robot (``SandWindowCfg.turn_with_robot``),
  so one window serves straight walks, circles and drifting headings alike.
* decoded stiffness: the student's mean decoded eta over the alive steps; on the layered ``transition`` course
  also per medium, with the swings there (``layer_stats``; ``table_transition``, ``fig_mpm_transition.png``).

Outputs under ``out_dir``: ``episodes.jsonl`` (one line per finished episode; the resume state),
``summary.json`` (metrics per group, throughput, config), the paper-shaped tables (``tables_mpm``), figures
(``figures_mpm``) and ``recordings/<terrain>__<scenario>__v<speed>.mcap`` (the best walk of every group: a success
if any, else the longest time alive; ``.json`` beside it names the episode).

Where the parts live: the config and episodes in :mod:`gmloco.eval.g1.config`, a cell's sand in
:mod:`~gmloco.eval.g1.lanes`, the episode loop in :mod:`~gmloco.eval.g1.cell`, the time box around it in
:mod:`~gmloco.eval.g1.timebox` (on the GPU cost model of :mod:`~gmloco.eval.g1.cost`), the metrics of one episode
in :mod:`~gmloco.eval.g1.score`, the window report in :mod:`~gmloco.eval.g1.window_report`, and reading and
summarising ``episodes.jsonl`` in :mod:`gmloco.eval.metrics.episodes`; this module runs them and writes the outputs.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from gmloco.eval.g1.cell import run_cell
from gmloco.eval.g1.config import EpisodeSpec, G1EvalCfg, episode_batches, episode_specs
from gmloco.eval.g1.cost import FIT_PROBE_S, CellCost
from gmloco.eval.g1.policy import load_policy
from gmloco.eval.g1.score import score_episode
from gmloco.eval.g1.timebox import cell_prior_cost, lanes_in_time_box
from gmloco.eval.g1.window_report import report_window
from gmloco.eval.metrics.episodes import read_episodes, summarize

__all__ = ["recording_rank", "resume_problem", "run", "write_outputs"]


def _recording_path(out: Path, spec: EpisodeSpec) -> Path:
    return out / "recordings" / f"{spec.terrain}__{spec.scenario}__v{spec.speed:g}.mcap"


_UNRECORDED = (False, -1.0)
"""Rank of a group without a recording: any episode beats it."""


def recording_rank(row: dict[str, Any]) -> tuple[bool, float]:
    """How well an episode shows its group's walk: successes first, then the longer time alive."""
    return bool(row.get("success")), float(row.get("alive_s") or 0.0)


def _recorded_ranks(out: Path) -> dict[str, tuple[bool, float]]:
    """Rank of each group's recording so far, from its sidecar (``recordings/<group>.json``)."""
    ranks = {}
    for side in (out / "recordings").glob("*.json"):
        try:
            doc = json.loads(side.read_text())
            ranks[doc["group"]] = (bool(doc["success"]), float(doc["alive_s"]))
        except (OSError, ValueError, KeyError):
            continue  # a damaged sidecar: the group is recorded again
    return ranks


def _record(log: dict[str, Any], row: dict[str, Any], cfg: G1EvalCfg, out: Path) -> None:
    """MCAP recording of one episode, with a sidecar saying which (``recordings/<group>.json``)."""
    from gmloco.eval.g1.record import write_episode_mcap

    spec: EpisodeSpec = log["spec"]
    path = _recording_path(out, spec)
    path.parent.mkdir(parents=True, exist_ok=True)
    notes = f"gmloco MPM eval episode {spec.key}: voxel {cfg.solver.voxel_size} m, moving window {cfg.window.moving}"
    write_episode_mcap(path, log, {"policy": Path(cfg.policy_path).name, "material": spec.terrain, "notes": notes,
                                   "end_reason": "completed" if row["success"] else row["reason"]})  # fmt: skip
    side = {"group": spec.group, "key": spec.key, "success": bool(row["success"]), "alive_s": row["alive_s"],
            "reason": row["reason"], "mcap": path.name}  # fmt: skip
    tmp = path.with_suffix(".json.tmp")  # tmp + replace: a kill never leaves half a sidecar
    tmp.write_text(json.dumps(side) + "\n")
    tmp.replace(path.with_suffix(".json"))


def resume_problem(cfg: G1EvalCfg) -> str | None:
    """Why resuming ``cfg.out_dir`` would mix sand windows (one sentence), or None.

    The folder's ``summary.json`` records the window its episodes walked on (without ``turn_with_robot``: a run
    before the window turned, on the grid's axes); a resume at another window would pool two settings in one row.
    """
    out = Path(cfg.out_dir)
    if not cfg.resume or not (out / "episodes.jsonl").is_file() or not (out / "summary.json").is_file():
        return None
    try:
        recorded = json.loads((out / "summary.json").read_text())["cfg"]["window"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    recorded = {"turn_with_robot": False} | dict(recorded)
    now = _jsonable(asdict(cfg.window))
    diff = [f"{k} {recorded.get(k)!r} -> {v!r}" for k, v in now.items() if k in recorded and recorded[k] != v]
    if not diff:
        return None
    flag = " (--window-fixed-axes for a run on the grid's axes)" if any("turn_with_robot" in d for d in diff) else ""
    return (
        f"{out} holds episodes walked on another sand window ({', '.join(diff)}); resume it with its own window"
        f"{flag}, or pass another --out"
    )


def run(cfg: G1EvalCfg) -> tuple[dict[str, float], bool]:
    """Run (or resume) the evaluation; return (summary metrics, complete).

    Appends each episode to ``episodes.jsonl`` as it finishes, and writes ``summary.json``, tables and figures at
    the end of the call. Stops early when ``max_minutes`` is reached (complete = False) with every finished episode
    kept; the episodes still running then are dropped, since they are unfinished.

    Raises:
        ValueError: The folder's episodes walked on another sand window (``resume_problem``).
    """
    if (problem := resume_problem(cfg)) is not None:
        raise ValueError(problem)
    out = Path(cfg.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    log_path = out / "episodes.jsonl"
    if not cfg.resume and log_path.exists():
        log_path.unlink()
    rows = read_episodes(log_path, repair=True) if log_path.exists() else []
    done = {r["key"] for r in rows}
    # each group's recording is its best walk (recording_rank): earlier calls' picks, then this call's best so far
    recorded = _recorded_ranks(out)
    for r in rows:  # runs before the square-window runs recorded a group's first episode and wrote no sidecar
        spec = _spec_of(r)
        if spec.group not in recorded and _recording_path(out, spec).exists():
            recorded[spec.group] = recording_rank(r)
    best: dict[str, tuple[tuple[bool, float], dict[str, Any], dict[str, Any]]] = {}
    todo = [s for s in episode_specs(cfg) if s.key not in done]
    policy = load_policy(cfg.policy_path, min(cfg.robots_per_batch, max(len(todo), 1)))
    t0, complete = time.perf_counter(), True
    deadline = None if cfg.max_minutes is None else t0 + 60.0 * cfg.max_minutes
    pending = episode_batches(todo, len(todo) if cfg.refill else cfg.robots_per_batch)
    costs: dict[tuple[str, str], CellCost] = {}  # measured per (terrain, scenario) in this call
    ended = set(done)  # episodes in the log, this call's included
    probe_s = FIT_PROBE_S if deadline is not None and cfg.fit_time_box else None

    def on_episode(lg: dict[str, Any]) -> None:
        """Score one finished episode, keep it if it is its group's best walk so far, append it to the log."""
        row = score_episode(lg["spec"], cfg, lg)
        ended.add(row["key"])
        group, rank = lg["spec"].group, recording_rank(row)
        held = best[group][0] if group in best else recorded.get(group, _UNRECORDED)
        if cfg.record_mcap and rank > held:
            best[group] = (rank, lg, row)
        rows.append(row)
        with log_path.open("a") as f:
            f.write(json.dumps(row) + "\n")

    cells = 0
    while pending:
        batch = pending.pop(0)
        if deadline is not None and time.perf_counter() > deadline:
            complete = False
            break
        cell, cell_cfg = (batch[0].terrain, batch[0].scenario), cfg
        if deadline is not None and cfg.fit_time_box:  # measured cost of its kind, else the H200 prior
            cost = costs[cell] if cell in costs else cell_prior_cost(batch, cfg)
            lanes = lanes_in_time_box(batch, cfg, cost, deadline - time.perf_counter(), prior=cell not in costs)
            if lanes == 0:
                complete = False
                break
            cell_cfg = replace(cfg, robots_per_batch=lanes)
            if not cfg.refill:  # lanes do not take further episodes: the rest waits for the next batch
                batch, rest = batch[:lanes], batch[lanes:]
                if rest:
                    pending.insert(0, rest)
        cells += 1
        lanes = min(len(batch), cell_cfg.robots_per_batch)
        label = f"cell {cells} ({batch[0].terrain}/{batch[0].scenario}: {len(batch)} episodes, {lanes} lanes)"
        outcome = run_cell(batch, cell_cfg, policy, on_episode, deadline, label, probe_s)
        _write_recordings(best, recorded, cfg, out)  # after every cell, so a time box keeps them
        if outcome.cost is not None:
            costs[cell] = outcome.cost
        if outcome.stopped == "no_fit":  # its unfinished episodes go back, to be cut to what fits
            pending.insert(0, [s for s in batch if s.key not in ended])
        elif not outcome.finished:
            complete = False  # the time box ended inside the cell: its running episodes are unfinished, not kept
            break
    summary = summarize(rows)
    wall = time.perf_counter() - t0
    summary["throughput/episodes_this_call"] = float(len(rows) - len(done))
    summary["throughput/episodes_per_minute"] = 60.0 * (len(rows) - len(done)) / max(wall, 1e-9)
    write_outputs(out, cfg, rows, summary, complete)
    report_window(rows, cfg.window)
    return summary, complete


def _write_recordings(best: dict[str, Any], recorded: dict[str, tuple[bool, float]], cfg: G1EvalCfg, out: Path) -> None:
    """Write the groups' best walks held in ``best`` (emptied) and remember their ranks in ``recorded``."""
    import sys

    for group, (rank, lg, row) in list(best.items()):
        try:
            _record(lg, row, cfg, out)
            recorded[group] = rank
        except ImportError as exc:  # no mcap / foxglove schemas installed: keep the episodes, say why
            print(f"recording of {group} skipped: {exc}", file=sys.stderr, flush=True)
        del best[group]


def _spec_of(row: dict[str, Any]) -> EpisodeSpec:
    """The spec fields a recording's path needs, from an episode row."""
    return EpisodeSpec(terrain=row["terrain"], scenario=row["scenario"], speed=float(row["speed"]), index=0)


def write_outputs(
    out: Path,
    cfg: G1EvalCfg,
    rows: list[dict[str, Any]],
    summary: dict,
    complete: bool,
    run_dirs: list[Path] | None = None,
) -> None:
    """``summary.json`` (temporary file + replace), the tables and the figures of ``rows`` under ``out``.

    ``run_dirs``: the folders whose ``recordings/`` hold the episodes' recordings (default: ``out``).
    """
    from gmloco.eval.report.figures_mpm import write_figures
    from gmloco.eval.report.tables_mpm import write_tables

    policy = cfg.policy_name or Path(cfg.policy_path).parent.name or Path(cfg.policy_path).stem
    tables = write_tables(rows, out, policy)
    try:  # the GPU image may lack matplotlib: the numbers must not be lost for a figure
        figures, note = (write_figures(rows, out, policy, cfg.episode_s, run_dirs) if rows else []), ""
    except ImportError as exc:
        figures, note = [], f"figures skipped: {exc}"
    from gmloco.eval.report.tables_mpm import paper_metrics, table_terrains

    doc = {"complete": complete, "policy": cfg.policy_path, "cfg": _jsonable(asdict(cfg)), "metrics": summary,
           "paper_metrics": paper_metrics(table_terrains(rows, policy)),
           "tables": [str(p.name) for p in tables], "figures": [str(p.name) for p in figures],
           "note": note}  # fmt: skip
    tmp = out / "summary.json.tmp"
    tmp.write_text(json.dumps(doc, indent=1))
    tmp.replace(out / "summary.json")


def _jsonable(obj: Any) -> Any:
    return json.loads(json.dumps(obj, default=str))
