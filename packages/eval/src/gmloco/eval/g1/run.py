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
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from gmloco.eval.g1.cost import FIT_PROBE_S, CellCost, cell_seconds, fit_lanes, prior_cost
from gmloco.eval.g1.policy import load_policy
from gmloco.eval.metrics.locomotion import (
    FailureCfg,
    circular_path,
    course_finished_at,
    episode_outcome,
    metric_heading_error_deg,
    metric_path_error,
    metric_velocity_tracking_error,
    metric_yaw_tracking_error,
    quat_wxyz_to_roll_pitch_yaw,
    swing_clearance,
)
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.window import SandWindowCfg, reach_within_window

__all__ = [
    "REACH_QUANTILE",
    "WINDOW_EXIT_GRACE_S",
    "WINDOW_EXIT_MARGIN_M",
    "EpisodeSpec",
    "G1EvalCfg",
    "build_cell_scene",
    "cell_minutes_left",
    "check_grid_capacity",
    "covering_window",
    "episode_batches",
    "episode_specs",
    "heading_turn_deg",
    "lane_failed",
    "load_policy",
    "reach_fits",
    "read_episodes",
    "report_window",
    "resume_problem",
    "run",
    "run_cell",
    "score_episode",
    "sole_reach_max",
    "summarize",
    "window_exit_cause",
    "window_exit_time",
    "write_outputs",
]  # fmt: skip

Scenario = Literal["straight", "circle"]


@dataclass(frozen=True)
class G1EvalCfg:
    """The MPM evaluation of one policy."""

    policy_path: str = "artifacts/ppo_rft3d/policy.onnx"
    """Exported policy: gmloco student format (``obs`` + ``history``) or mjlab's actor export (``obs`` only)."""
    out_dir: str = "results/mpm_eval"
    """Output folder."""
    policy_name: str = ""
    """The policy's name in tables and figures; empty: the name of the policy file's folder."""
    terrains: tuple[str, ...] = ("dry_sand",)
    """Terrains (``gmloco.eval.mpm.window_terrain.terrain_cfg`` names: a preset medium, ``<medium>_rough``,
    ``<medium>_deep``, ``transition``)."""
    scenarios: tuple[Scenario, ...] = ("straight",)
    """Command scenarios."""
    speeds: tuple[float, ...] = (1.0, 1.5, 2.0, 2.5)
    """Forward-speed commands [m/s]; episode k of a cell uses ``speeds[k % len(speeds)]``."""
    num_episodes: int = 100
    """Episodes per (terrain, scenario)."""
    shard: int = 0
    """Which share of each cell's episodes this run scores: those whose index k has ``k % shards == shard``."""
    shards: int = 1
    """Shares a cell's episodes are split into (one run folder, e.g. one GPU, each; ``paper_tables`` pools the
    folders). With as many shares as speeds, each share walks one speed."""
    episode_s: float = 10.0
    """Episode length = course time limit [s]."""
    circle_radius: float = 2.0
    """Radius of the circular walk [m] (yaw rate = v / R)."""
    course_slack: float = 0.2
    """Fraction of the commanded path that may be left when time runs out and still count as finished [-]."""
    bed_depth: float = 0.30
    """Sand depth of the flat and rough terrains [m] (the deep terrain has its own 0.30 m); a loaded sole of a
    walking G1 reaches 20-30 cm on MPM sand (``results/mpm_eval/convergence/batched_cuts``)."""
    window: SandWindowCfg = field(default_factory=lambda: SandWindowCfg(length=1.4, width=0.6))
    """Sand window of each robot (``moving=False``: a static bed covering the course, the naive baseline). 1.4 m
    walks as 1.8 m does, 0.6 m wide as 1.0 m does (``docs/mpm_eval.md``); a 1.0 x 0.5 m window was rejected. The
    window turns with the robot's heading (within ``turn_step``), so straight walks, circles and drifting headings
    share one setting; ``turn_with_robot=False`` gives the box of the grid's axes the earlier tables used."""
    bed_margin: float = 0.6
    """Static beds: margin around the commanded path [m]."""
    robots_per_batch: int = 32
    """Robots (lanes) simulated together in one MPM solver."""
    refill: bool = True
    """Start a lane's next episode as soon as its robot falls or its episode ends (one solver per cell, episodes
    of any length share it); False: one solver per batch of ``robots_per_batch`` episodes, lanes idle after."""
    retire_idle_lanes: bool = True
    """Take a lane's sand out of the MPM solve once its robot has no episode left (``G1MpmScene.retire_robots``):
    the cell's tail, while its last robots walk, costs only their sand. False: idle lanes keep their sand in the
    solve (the runs up to the ablation-circle runs)."""
    lane_gap: float = 2.0
    """Free space between neighbouring lanes' windows or paths [m] (robots may drift)."""
    cell_capacity_factor: float = 1.5
    """Grid capacity = factor x particles / particles-per-cell (fixed capacity: CUDA graph); 0 = unbounded.
    The rheology solver sweeps the whole capacity, so its cost grows with the factor: 1.5 gave 1.46x the
    robot-frames/s of 3.0 (H200, 32 robots, results/mpm_eval/convergence/grid_capacity_solvers); an overflow stops the cell with an error."""
    solver: MpmSolverCfg = field(
        default_factory=lambda: MpmSolverCfg(voxel_size=0.03, frame_dt=0.005, rigid_substeps=1, max_iterations=500)
    )
    """MPM numerics: 3 cm voxels, 5 ms frames (200 Hz coupling), 500 rheology iterations per frame, the setting the
    convergence check accepted (the accepted-setting runs, ``docs/mpm_eval.md``): 500 against 1000 iterations and a 1.4 m window
    against 1.8 m are accepted; 350 iterations, 4 or 5 cm voxels, a 20 cm bed and 10 ms frames are rejected. A 3 cm
    frame of a G1 walk does not reach the 1e-4 tolerance within 1000 iterations, so the cap is the cost. The
    pipeline's smoke scale uses fast, unconverged numerics (``conf/scale/smoke.yaml``)."""
    failure: FailureCfg = field(default_factory=FailureCfg)
    """Failure rules."""
    record_mcap: bool = True
    """Write the best walk of every (terrain, scenario, speed) group as an MCAP recording (``recordings/``): a success
    if any, else the longest time alive; a sidecar JSON names the episode. Runs before the square-window runs recorded the
    group's first episode to end."""
    seed: int = 0
    """Seed of the sand."""
    device: str | None = None
    """Warp device."""
    max_minutes: float | None = None
    """Stop (resumable) after this much wall time [min]."""
    fit_time_box: bool = True
    """With ``max_minutes``: start only walks that can end before it (``g1_eval_fit``): a cell whose running walks
    would not end in the time left if no robot fell is stopped after ~30 s of stepping and rebuilt with the lanes that
    fit, a later cell of the same (terrain, scenario) gets those lanes before it is built, the first cell of a
    (terrain, scenario) is sized before its build by an H200's frame-cost line (``g1_eval_fit.prior_cost``: none
    when not one walk would end), and a freed lane takes the next episode only if a whole walk still fits. False:
    cells run until the time box drops them."""
    resume: bool = True
    """Keep finished episodes in ``episodes.jsonl``; else start fresh."""


@dataclass(frozen=True)
class EpisodeSpec:
    """One episode."""

    terrain: str
    scenario: Scenario
    speed: float
    index: int

    @property
    def key(self) -> str:
        """Unique id in ``episodes.jsonl``."""
        return f"{self.terrain}/{self.scenario}/{self.index}"

    @property
    def group(self) -> str:
        """(terrain, scenario, speed) group id."""
        return f"{self.terrain}/{self.scenario}/v{self.speed:g}"


def episode_specs(cfg: G1EvalCfg) -> list[EpisodeSpec]:
    """The run's episodes (its share of each cell: ``shard`` of ``shards``), cell-major.

    Raises:
        ValueError: ``shard`` is not one of ``0 .. shards - 1``.
    """
    if not 0 <= cfg.shard < cfg.shards:
        raise ValueError(f"shard {cfg.shard} of {cfg.shards}: the share must be 0 .. {cfg.shards - 1} (--shard I/N)")
    return [
        EpisodeSpec(t, s, float(cfg.speeds[k % len(cfg.speeds)]), k)
        for t in cfg.terrains
        for s in cfg.scenarios
        for k in range(cfg.num_episodes)
        if k % cfg.shards == cfg.shard
    ]


def episode_batches(specs: list[EpisodeSpec], size: int) -> list[list[EpisodeSpec]]:
    """Split episodes into batches of at most ``size`` that share a (terrain, scenario) cell."""
    out: list[list[EpisodeSpec]] = []
    for s in specs:
        if out and len(out[-1]) < size and (out[-1][0].terrain, out[-1][0].scenario) == (s.terrain, s.scenario):
            out[-1].append(s)
        else:
            out.append([s])
    return out


def command(spec: EpisodeSpec, cfg: G1EvalCfg) -> tuple[float, float, float]:
    """(v_x, v_y, w_z) of an episode [m/s, m/s, rad/s]."""
    wz = spec.speed / cfg.circle_radius if spec.scenario == "circle" else 0.0
    return (spec.speed, 0.0, wz)


def _window_and_lanes(batch: list[EpisodeSpec], cfg: G1EvalCfg) -> tuple[SandWindowCfg, float]:
    """The batch's sand window and its lane spacing [m].

    A moving window follows the pelvis (centred ``lead`` along its heading) and, by default, turns with it: every
    scenario uses the same window, and the lanes are spaced for any heading (the window's diagonal plus twice its
    lead). A window that does not turn (``turn_with_robot=False``) becomes a square of side ``max(length, width)``
    on a circle, whose heading sweeps all directions: along any heading it then reaches at least as far as the
    straight window does along x, at ``(side / width)`` times its cost. A static window covers the fastest course.
    """
    circle = batch[0].scenario == "circle"
    if cfg.window.moving:
        window = cfg.window
        if window.turn_with_robot:
            span = math.hypot(window.length, window.width) + 2.0 * abs(window.lead)
        else:
            if circle:
                side = max(window.length, window.width)
                window = replace(window, length=side, width=side)
            span = window.width
        span += 2.0 * cfg.circle_radius if circle else 0.0
        return window, span + cfg.lane_gap
    v = max(s.speed for s in batch)
    vx, _, wz = command(replace(batch[0], speed=v), cfg)
    xy, _ = circular_path(vx, wz, cfg.episode_s, 0.05)
    lo, hi = xy.min(axis=0) - cfg.bed_margin, xy.max(axis=0) + cfg.bed_margin
    lo[1], hi[1] = min(lo[1], -0.5 * cfg.window.width), max(hi[1], 0.5 * cfg.window.width)
    c, size = 0.5 * (lo + hi), hi - lo
    win = replace(cfg.window, length=float(size[0]), width=float(size[1]), lead=float(c[0]), offset_y=float(c[1]))
    return win, float(size[1]) + cfg.lane_gap


def lane_failed(q: np.ndarray, surface_z: float, failure: FailureCfg) -> bool:
    """The paper's fall rule on one pelvis pose ``q`` = (p, q_xyzw): too low above the sand, or tilted too far."""
    roll, pitch, _ = quat_wxyz_to_roll_pitch_yaw(np.array([[q[6], q[3], q[4], q[5]]]))[0]
    return bool(q[2] - surface_z < failure.min_base_height or max(abs(roll), abs(pitch)) > failure.max_tilt)


def cell_minutes_left(steps_left: list[int], queued: int, steps: int, frames_per_step: int, fps: float) -> float:
    """Minutes until a cell's last lane ends if no robot falls: its lanes step together at ``fps`` frames/s.

    Args:
        steps_left: Policy steps still to go of each running episode.
        queued: Episodes not started yet (each ``steps`` long; a lane takes one as its episode ends).
        steps: Policy steps of a whole episode.
        frames_per_step: MPM frames per policy step.
        fps: Frames per second of the solver (all lanes at once).
    """
    if not steps_left or fps <= 0.0:
        return 0.0
    ends = sorted(steps_left)
    for _ in range(queued):  # the lane that frees first takes the next episode
        ends[0] += steps
        ends.sort()
    return ends[-1] * frames_per_step / fps / 60.0


def build_cell_scene(specs: list[EpisodeSpec], cfg: G1EvalCfg, policy: Any) -> tuple[Any, Any, MpmSolverCfg]:
    """The captured ``G1MpmScene`` of a cell's first ``robots_per_batch`` episodes, its terrain and solver cfg.

    One lane per robot, each commanded as its episode; the active-cell capacity is sized from the windows
    (``cell_capacity_factor``); ``policy`` is reloaded for the lane count if it was built for another.
    """
    from gmloco.eval.mpm.g1_scene import G1MpmScene, G1MpmSceneCfg

    n = min(cfg.robots_per_batch, len(specs))
    terrain, window, lane, per_lane = _cell_sand(specs, cfg)
    solver = cfg.solver
    if cfg.cell_capacity_factor > 0 and solver.grid_type != "dense":
        per_cell = window.particles_per_voxel**3
        est = per_lane * n
        solver = replace(solver, max_active_cell_count=int(cfg.cell_capacity_factor * est / per_cell) + 64)
    scene_cfg = G1MpmSceneCfg(terrain=terrain, window=window, num_robots=n, lane_spacing=lane, solver=solver,
                              commands=tuple(command(s, cfg) for s in specs[:n]),
                              seed=cfg.seed * 100_003 + specs[0].index, device=cfg.device)  # fmt: skip
    if hasattr(policy, "num_robots") and policy.num_robots != n:
        policy = load_policy(cfg.policy_path, n)
    policy.reset()
    scene = G1MpmScene(scene_cfg, policy)
    scene.capture()
    return scene, terrain, solver


def run_cell(
    specs: list[EpisodeSpec],
    cfg: G1EvalCfg,
    policy: Any,
    on_episode: Callable[[dict[str, Any]], None],
    deadline: float | None = None,
    label: str = "",
    probe_s: float | None = None,
) -> CellOutcome:
    """Simulate the episodes of one (terrain, scenario) cell in lanes of one MPM solver.

    ``min(robots_per_batch, len(specs))`` robots start together, one per lane. A lane's episode ends when its
    robot falls (``lane_failed``, checked at every policy step) or after ``episode_s``; its log (policy rate, up
    to and including the failing sample) goes to ``on_episode`` at once. With ``cfg.refill`` the lane then starts
    the next episode of ``specs`` (``G1MpmScene.reset_robots``: start pose, fresh sand); else it stays idle, and
    with ``cfg.retire_idle_lanes`` its sand leaves the solve (``G1MpmScene.retire_robots``). The cell ends when
    every lane is idle. At ``deadline`` (``time.perf_counter`` s) the episodes still running are
    dropped, those finished before are already out. A progress line goes to stderr about every 30 s.

    With ``probe_s`` and a deadline, the cell's cost is measured once it has stepped ``probe_s`` seconds
    (:class:`~gmloco.eval.g1.cost.CellCost`); if its running walks would then not all end before the deadline
    even if no robot fell, it stops at once (``outcome.stopped == "no_fit"``: its running episodes dropped, the
    caller rebuilds it with the lanes that fit). After that a freed lane takes the next episode only if a whole walk
    would end before the deadline at the measured cost; the episodes it leaves are for the next call.
    """
    import sys

    from gmloco.eval.mpm.window_terrain import terrain_surface_height

    t0 = time.perf_counter()
    scene, terrain, solver = build_cell_scene(specs, cfg, policy)
    n = min(cfg.robots_per_batch, len(specs))
    lane_spec, queue = list(specs[:n]), list(specs[n:]) if cfg.refill else []
    build_s = time.perf_counter() - t0
    k = scene.frames_per_policy
    steps = round(cfg.episode_s / (scene.frame_dt * k))
    start, active, done = [0] * n, [True] * n, 0
    last = t_steps = time.perf_counter()
    cost: CellCost | None = None
    while True:
        if scene.frame % k == 0 and scene.base_q:
            rows = len(scene.base_q)
            resets, retired, checked = [], [], False
            for r in range(n):
                if not active[r]:
                    continue
                q = scene.base_q[-1][r]
                surf = float(terrain_surface_height(terrain, np.array(q[0]), np.array(q[1] - scene.lane_y[r])))
                if rows - start[r] < steps and not lane_failed(q, surf, cfg.failure):
                    continue
                if not checked:  # an episode is kept only if the grid held all its cells (one device sync)
                    scene.sync()
                    check_grid_capacity(scene, solver)
                    checked = True
                log = _lane_log(scene, r, start[r], rows, lane_spec[r], terrain, build_s, n)
                on_episode(log | {"elapsed_s": time.perf_counter() - t_steps})
                done += 1
                if queue and _walk_fits(cost, steps * k, deadline):
                    lane_spec[r], start[r] = queue.pop(0), rows
                    resets.append(r)
                else:  # no episode left, or none that could end before the deadline (then left for the next call)
                    active[r] = False
                    retired.append(r)
            scene.reset_robots(resets, [command(lane_spec[r], cfg) for r in resets],
                               [lane_spec[r].index + 1 for r in resets])  # fmt: skip
            if retired and cfg.retire_idle_lanes and any(active):
                scene.retire_robots(retired)
            if not any(active):
                break
            now = time.perf_counter()
            if deadline is not None and now > deadline:
                print(f"{label}: time box reached with {done}/{len(specs)} episodes done; {sum(active)} running "
                      "episodes dropped", file=sys.stderr, flush=True)  # fmt: skip
                return CellOutcome(False, "time_box", cost)
            if cost is None and probe_s is not None and now - t_steps >= probe_s and scene.frame > 0:
                scene.sync()
                cost = CellCost(sum(active), (time.perf_counter() - t_steps) / scene.frame, build_s)
                longest = max(steps - (rows - start[r]) for r in range(n) if active[r])
                need = cell_seconds(cost, cost.lanes, longest * k, build=False)  # its running walks, none falling
                if deadline is not None and now + need > deadline:
                    print(f"{label}: its walks need ~{need / 60:.1f} min if none falls, {(deadline - now) / 60:.1f} "
                          f"min are left: stopped after {scene.frame} frames to refit it into the time box "
                          f"({sum(active)} running episodes dropped)", file=sys.stderr, flush=True)  # fmt: skip
                    return CellOutcome(False, "no_fit", cost)
            if now - last > 30.0:
                scene.sync()
                check_grid_capacity(scene, solver)
                left = [steps - (rows - start[r]) for r in range(n) if active[r]]
                eta = cell_minutes_left(left, len(queue), steps, k, scene.frames_per_second)
                print(f"{label}: {done}/{len(specs)} episodes done, {sum(active)} running, "
                      f"{scene.frames_per_second:.1f} frames/s, ~{eta:.0f} min left if none falls",
                      file=sys.stderr, flush=True)  # fmt: skip
                last = now
        scene.step()
    scene.sync()
    check_grid_capacity(scene, solver)
    if queue:
        print(f"{label}: {len(queue)} episodes not started: they could not end before the time box",
              file=sys.stderr, flush=True)  # fmt: skip
        return CellOutcome(False, "time_box", cost)
    return CellOutcome(True, None, cost)


def _walk_fits(cost: CellCost | None, frames: int, deadline: float | None) -> bool:
    """Whether a walk of ``frames`` frames started now ends before ``deadline`` at ``cost`` (True: not measured)."""
    if cost is None or deadline is None:
        return True
    return time.perf_counter() + cell_seconds(cost, cost.lanes, frames, build=False) <= deadline


@dataclass(frozen=True)
class CellOutcome:
    """How :func:`run_cell` ended."""

    finished: bool
    """Every episode of the cell ended and was handed out."""
    stopped: Literal["time_box", "no_fit"] | None = None
    """Why it stopped early: the deadline passed, or its walks would not have ended before it (refit)."""
    cost: CellCost | None = None
    """The cell's measured cost (with a probe), for fitting the next cell of its (terrain, scenario)."""


def check_grid_capacity(scene: Any, solver: MpmSolverCfg) -> None:
    """Raise if the sparse grid outgrew its reserved active cells (the frames since then are not valid sand)."""
    if solver.max_active_cell_count <= 0 or solver.grid_type != "sparse":
        return
    try:
        scene.mpm.check_sparse_grid_rebuild_status()
    except RuntimeError as exc:
        raise RuntimeError(
            f"the MPM grid needed more than its {solver.max_active_cell_count} reserved active cells ({exc}); "
            "the episodes of this cell are not valid: rerun it with a larger --cell-capacity-factor"
        ) from exc


def _lane_log(
    scene: Any, r: int, a: int, b: int, spec: EpisodeSpec, terrain: Any, build_s: float, n: int
) -> dict[str, Any]:
    """One episode's log: lane ``r``'s policy-rate samples ``a:b`` (``score_episode``'s input)."""
    from gmloco.eval.mpm.g1_scene import LOG_FIELDS
    from gmloco.eval.mpm.window_terrain import terrain_surface_height

    arr = {name: np.asarray(getattr(scene, name)[a:b])[:, r] for name in LOG_FIELDS}
    q = arr["base_q"]
    surf = terrain_surface_height(terrain, q[:, 0], q[:, 1] - scene.lane_y[r])
    return arr | {
        "spec": spec, "dt": scene.frame_dt * scene.frames_per_policy, "base_height": q[:, 2] - surf,
        "terrain_cfg": terrain, "command": tuple(float(c) for c in scene.commands[r]),
        "joint_names": scene.spec.joint_names, "kp": scene.spec.kp, "kd": scene.spec.kd, "start_xy": q[0, :2].copy(),
        "robot_mass": scene.robot_mass, "particles": scene.particle_count, "batch_size": n, "build_s": build_s,
        "sim_s": scene.wall_time, "frames": scene.frame, "depth": terrain.depth,
    }  # fmt: skip


def _cell_sand(specs: list[EpisodeSpec], cfg: G1EvalCfg) -> tuple[Any, SandWindowCfg, float, int]:
    """A cell's terrain, sand window, lane spacing [m] and particles per lane, as ``build_cell_scene`` builds it."""
    from gmloco.eval.mpm.window_terrain import terrain_cfg

    terrain = terrain_cfg(specs[0].terrain, depth=cfg.bed_depth)
    window, lane = _window_and_lanes(specs, cfg)
    return terrain, window, lane, _window_particles(window, terrain.depth, cfg.solver.voxel_size)


def _window_particles(window: SandWindowCfg, depth: float, voxel: float) -> int:
    """Particles of one robot's window in the MPM solve: nx ny columns of nz (as :class:`SandWindow` sizes it).

    A turning window holds nx ny columns to within its perimeter's cells (``window_slots`` reserves up to
    ``sqrt(2) (nx + ny) + 2`` more slots for its worst heading); its free slots are parked, out of the solve.
    """
    h = voxel / window.particles_per_voxel
    nx, ny = max(1, math.ceil(window.length / h)), max(1, math.ceil(window.width / h))
    return nx * ny * max(1, round(depth / h))


def score_episode(spec: EpisodeSpec, cfg: G1EvalCfg, log: dict[str, Any]) -> dict[str, Any]:
    """Paper metrics of one episode log (see the module docstring)."""
    dt, q, qd = log["dt"], log["base_q"], log["base_qd"]
    quat_wxyz = np.concatenate([q[:, 6:7], q[:, 3:6]], axis=1)
    rpy = quat_wxyz_to_roll_pitch_yaw(quat_wxyz)
    v, _, wz = command(spec, cfg)
    cmd_xy, _ = circular_path(v, wz, cfg.episode_s, dt, start_xy=tuple(log["start_xy"]))
    finished_at = course_finished_at(q[:, :2], cmd_xy, dt, cfg.course_slack)
    height = np.asarray(log.get("base_height", q[:, 2]))
    out = episode_outcome(height, rpy[:, 0], rpy[:, 1], dt, finished_at, cfg.failure)
    alive = max(out.alive_steps, 1)
    yaw = rpy[:, 2]
    c, s = np.cos(yaw), np.sin(yaw)
    v_yaw = np.stack([c * qd[:, 0] + s * qd[:, 1], -s * qd[:, 0] + c * qd[:, 1]], axis=1)
    fz = log["foot_force"][:, :, 2].sum(axis=1) if len(log["foot_force"]) else np.zeros(1)
    sink = np.asarray(log["sinkage"])[:alive]
    swing = swing_clearance(-np.asarray(log["foot_sinkage"]), np.asarray(log["foot_force"])[..., 2], alive)
    eta = np.asarray(log.get("eta", np.full(len(q), np.nan)), dtype=float)[:alive]
    exit_s = window_exit_time(log.get("sole_out"), dt, alive)
    behind, ahead, side = sole_reach_max(log.get("sole_reach"), alive)
    cause = window_exit_cause(log.get("sole_reach"), exit_s, dt, _window_and_lanes([spec], cfg)[0])
    early = exit_s is not None and exit_s < out.alive_steps * dt - WINDOW_EXIT_GRACE_S
    return {
        "key": spec.key, "terrain": spec.terrain, "scenario": spec.scenario, "speed": spec.speed,
        "success": out.success, "reason": out.reason, "alive_s": out.alive_steps * dt,
        "finished_at_s": finished_at,
        "vel_error": metric_velocity_tracking_error(np.tile([v, 0.0], (len(q), 1)), v_yaw, alive),
        "heading_error_deg": metric_heading_error_deg(yaw, wz, dt, alive),
        "yaw_error": metric_yaw_tracking_error(np.full(len(q), wz), qd[:, 5], alive),
        "path_error": metric_path_error(q[:alive, :2], cmd_xy),
        "support_ratio": float(fz[len(fz) // 2 :].mean() / (log["robot_mass"] * 9.81)),
        "max_sinkage": float(np.max(sink)) if len(sink) else float("nan"),
        "mean_sinkage": float(np.mean(sink)) if len(sink) else float("nan"),
        "swing_apex": swing.apex, "swing_lift": swing.lift, "swings": swing.swings,
        "eta_mean": float(np.mean(eta)) if np.isfinite(eta).any() else float("nan"),
        "layers": layer_stats(log, alive),
        # a sole that needed sand stood outside its sand window (no particles there): the window was too small
        "window_exit_s": exit_s, "window_exit_early": early, "window_exit_cause": cause,
        # the window is a box of the grid's axes: a robot that turned can step out of it within its reach
        "window_exit_turn": early and cause == "turn", "heading_turn_deg": heading_turn_deg(yaw, alive),
        # how much window the soles needed: their reach from the pelvis (yaw frame) while near or in the sand
        "sole_behind_m": behind, "sole_ahead_m": ahead, "sole_side_m": side,
        # a sole reached the rigid floor under the sand (the soles stand on it): the bed was too shallow there
        "floor_reached": bool(len(sink) and np.max(sink) >= log.get("depth", math.inf) - 0.005),
        "particles": log["particles"], "batch_size": log.get("batch_size", 1), "build_s": log["build_s"],
        "sim_s": log["sim_s"], "frames_per_s": log["frames"] / max(log["sim_s"], 1e-9),
        # the scene's frame at the episode's end and the wall seconds since its first frame, host work included
        # (``sim_s`` is the scene's stepping time: ``G1MpmScene.step`` and, since the square-window runs, every wait for the
        # frames in flight; before, the waits of the grid-capacity checks went uncounted and rates read ~8 % high)
        "end_frame": log["frames"], "elapsed_s": log.get("elapsed_s"),
    }  # fmt: skip


WINDOW_EXIT_GRACE_S = 0.25
"""A sole leaving the sand window this close to an episode's end (the fall under way) does not flag it [s]."""
FALL_EXIT_S = 0.75
"""An early window exit this close before the episode's fall counts as part of the fall [s]: the trailing sole of
a stumble. The reach-window runs reran the poppy-seed and deep-sand rows, whose exits (54 % and 37 % of their walks) came
0.26-0.72 s before the fall, at a window no sole left: the rows and their times alive did not change (0 of 100
each; Mann-Whitney p = 0.94 / 0.91; ``results/mpm_eval/table_rows/poppy_seed_deep_sand_reach/README.md``)."""


FALL_REASONS = ("tilt", "base_height")
"""Episode end reasons that are falls (``metrics.locomotion.episode_outcome``; not "timeout" or "success")."""


def exit_in_fall(row: dict[str, Any]) -> bool:
    """Whether an episode's early window exit came within ``FALL_EXIT_S`` before its fall (not a timeout).

    The walk was then already lost when its sole left the sand.
    """
    if not row.get("window_exit_early") or row.get("reason") not in FALL_REASONS:
        return False
    exit_s, alive = row.get("window_exit_s"), row.get("alive_s")
    return exit_s is not None and alive is not None and float(alive) - float(exit_s) <= FALL_EXIT_S


def window_exit_time(sole_out: Any, dt: float, alive: int) -> float | None:
    """First time [s] a sole corner that needed sand lay outside the window (``soles_outside``); None if never.

    ``sole_out``: per-sample counts ([T] or [T, 1]); None for logs written before the check existed.
    """
    if sole_out is None:
        return None
    counts = np.asarray(sole_out, dtype=float).reshape(len(sole_out), -1).sum(axis=1)[:alive]
    hit = np.flatnonzero(counts > 0)
    return float(hit[0] * dt) if len(hit) else None


WINDOW_EXIT_MARGIN_M = 0.02
"""Reach this close to the window's edge counts as beyond it (the window moves in whole particle columns) [m]."""


def window_exit_cause(reach: Any, exit_s: float | None, dt: float, window: SandWindowCfg) -> str | None:
    """Why the soles first left the sand window, from their reach at that sample (``sole_reach``, pelvis yaw frame).

    ``"turn"``: they lay within the window's extent measured along the robot's heading (behind, ahead, beside the
    pelvis, less ``WINDOW_EXIT_MARGIN_M``; for a turning window under its worst heading lag), so the exit came from
    the robot turning away from a window that does not turn with it. ``"reach"``: they reached beyond that extent
    (the window is too short or narrow, or a static bed). None without an exit or without a reach log (older runs).
    """
    if reach is None or exit_s is None:
        return None
    arr = np.asarray(reach, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 3 or not len(arr):
        return None
    k = min(round(exit_s / dt), len(arr) - 1)
    if not np.isfinite(arr[k]).all():
        return None
    return "turn" if window.moving and reach_fits(tuple(arr[k]), window) else "reach"


def reach_fits(reach: tuple[float, float, float], window: SandWindowCfg) -> bool:
    """Whether the soles' reach (behind, ahead, beside the pelvis) [m] lies within the window's extent.

    Measured along the robot's heading, less ``WINDOW_EXIT_MARGIN_M`` on every side; a turning window may lag the
    heading by its ``turn_step`` (``window.reach_within_window``).
    """
    return reach_within_window(window, (float(reach[0]), float(reach[1]), float(reach[2])), WINDOW_EXIT_MARGIN_M)


def heading_turn_deg(yaw: np.ndarray, alive: int) -> float:
    """Largest turn of the heading away from its start over the alive samples [deg] (yaw [rad], wrapped)."""
    yaw = np.asarray(yaw, dtype=float)[: max(alive, 1)]
    if not len(yaw):
        return math.nan
    turn = np.angle(np.exp(1j * (yaw - yaw[0])))
    return float(np.degrees(np.max(np.abs(turn))))


def sole_reach_max(reach: Any, alive: int) -> tuple[float, float, float]:
    """Largest reach of the soles behind / ahead of / beside the pelvis over the alive samples [m] (``sole_reach``).

    ``reach``: per-sample [T, 3]; NaN entries (soles in the air) are skipped; NaNs when absent (older logs).
    """
    arr = None if reach is None else np.asarray(reach, dtype=float)
    if arr is None or arr.ndim != 2 or arr.shape[1] != 3 or not np.isfinite(arr[:alive]).any():
        return math.nan, math.nan, math.nan
    b, a, s = np.nanmax(arr[:alive], axis=0)
    return float(b), float(a), float(s)


def layer_stats(log: dict[str, Any], alive: int) -> list[dict[str, Any]] | None:
    """Per medium of a layered course (``transition``): decoded eta and swings while the pelvis was over it.

    None for single-medium terrains. Each entry: ``medium``, ``steps`` (alive policy steps over it), ``eta_mean``,
    ``swing_apex`` / ``swing_lift`` [m] and ``swings`` (swings completed within one stretch over it; a swing that
    crosses a boundary counts for neither side), NaN where there are none.
    """
    from gmloco.eval.mpm.window_terrain import terrain_layer

    terrain = log.get("terrain_cfg")
    if terrain is None or len(terrain.materials) < 2:
        return None
    x = np.asarray(log["base_q"])[:alive, 0]
    layer = terrain_layer(terrain, x)
    height = -np.asarray(log["foot_sinkage"])[:alive]
    load = np.asarray(log["foot_force"])[:alive, :, 2]
    eta = np.asarray(log.get("eta", np.full(alive, np.nan)), dtype=float)[:alive]
    out = []
    for k, medium in enumerate(terrain.materials):
        on = layer == k
        runs = _runs(on)
        swings = [swing_clearance(height[a:b], load[a:b]) for a, b in runs]
        finite = eta[on][np.isfinite(eta[on])]
        out.append({"medium": medium, "steps": int(on.sum()), "swings": sum(sw.swings for sw in swings),
                    "eta_mean": float(finite.mean()) if len(finite) else float("nan"),
                    "swing_apex": _pooled(swings, "apex"), "swing_lift": _pooled(swings, "lift")})  # fmt: skip
    return out


def _pooled(parts: list[Any], key: str) -> float:
    """Swing-weighted mean of ``key`` over ``SwingClearance`` parts with a finite value (NaN if none)."""
    pairs = [(getattr(p, key), p.swings) for p in parts if p.swings and math.isfinite(getattr(p, key))]
    total = sum(w for _, w in pairs)
    return sum(v * w for v, w in pairs) / total if total else float("nan")


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, end) of every run of True in ``mask``."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist(), strict=True))


METRIC_KEYS = (
    "success", "vel_error", "heading_error_deg", "yaw_error", "path_error", "support_ratio", "max_sinkage", "mean_sinkage", "floor_reached",
    "swing_apex", "swing_lift", "eta_mean", "window_exit_early", "window_exit_turn", "heading_turn_deg",
    "sole_behind_m", "sole_ahead_m", "sole_side_m",
)  # fmt: skip


def summarize(rows: list[dict[str, Any]]) -> dict[str, float]:
    """Mean metrics per (terrain, scenario, speed), per (terrain, scenario) and over all episodes.

    The success rate comes with its 95 % Wilson interval (``success_lo95`` / ``success_hi95``).
    """
    from gmloco.eval.report.tables_mpm import wilson_interval

    groups: dict[str, list[dict[str, Any]]] = {"all": rows}
    for r in rows:
        groups.setdefault(f"{r['terrain']}/{r['scenario']}", []).append(r)
        groups.setdefault(f"{r['terrain']}/{r['scenario']}/v{r['speed']:g}", []).append(r)
    out: dict[str, float] = {}
    for g, rs in groups.items():
        out[f"{g}/num_episodes"] = float(len(rs))
        for k in METRIC_KEYS:
            vals = [float(r[k]) for r in rs if r.get(k) is not None and math.isfinite(float(r[k]))]
            name = "success_rate" if k == "success" else k
            out[f"{g}/{name}"] = float(np.mean(vals)) if vals else float("nan")
        out[f"{g}/success_lo95"], out[f"{g}/success_hi95"] = wilson_interval(
            sum(bool(r["success"]) for r in rs), len(rs)
        )
    return out


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


def read_episodes(path: Path, repair: bool = False) -> list[dict[str, Any]]:
    """Episode rows of an ``episodes.jsonl``, read up to the damage.

    Episodes are appended one line at a time, so a run killed mid-write can leave a partial last line: it is
    skipped with a note on stderr (with ``repair``, cut off the file so a resumed run appends after the last whole
    episode). A damaged line before the last means the file was edited: ValueError naming the line.
    """
    import sys

    text = path.read_text()
    lines = text.splitlines()
    rows: list[dict[str, Any]] = []
    for k, line in enumerate(lines):
        if not line.strip():
            continue
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError as exc:
            if k < len(lines) - 1:
                raise ValueError(f"{path}:{k + 1}: not an episode record ({exc}); remove the line or rerun with "
                                 "--fresh") from exc  # fmt: skip
            print(f"{path}: last line is a partial record (run stopped while writing); it is skipped",
                  file=sys.stderr)  # fmt: skip
            if repair:
                path.write_text("".join(f"{good}\n" for good in lines[:k]))
    return rows


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
            cost = costs[cell] if cell in costs else _prior_cost(batch, cfg)
            lanes = _fit_lanes(batch, cfg, cost, deadline - time.perf_counter(), prior=cell not in costs)
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


def _prior_cost(batch: list[EpisodeSpec], cfg: G1EvalCfg) -> CellCost:
    """``g1_eval_fit.prior_cost`` of ``batch``'s cell as ``build_cell_scene`` would build it."""
    per_lane = _cell_sand(batch, cfg)[3]
    return prior_cost(per_lane, min(cfg.robots_per_batch, len(batch)), cfg.solver.max_iterations)


def _fit_lanes(
    batch: list[EpisodeSpec], cfg: G1EvalCfg, cost: CellCost, seconds_left: float, prior: bool = False
) -> int:
    """Lanes for ``batch`` whose first walks all end within ``seconds_left`` [s] at its cell's ``cost`` (0: none).

    A lane's later walks (refill) start only if they too can end (``run_cell``). ``prior``: ``cost`` is the H200
    prior, not a measurement (said so in the message).
    """
    import sys

    frames = math.ceil(round(cfg.episode_s / cfg.solver.frame_dt, 6))
    lanes = min(len(batch), cfg.robots_per_batch)
    n = fit_lanes(cost, frames, seconds_left, lanes)
    if n == lanes:
        return n
    basis = " by the H200 frame-cost prior" if prior else ""
    if n == 0:
        print(f"time box: {seconds_left / 60:.1f} min left, one more {cfg.episode_s:g} s walk of "
              f"{batch[0].terrain}/{batch[0].scenario} needs ~{cell_seconds(cost, 1, frames) / 60:.1f} min{basis}; "
              f"{len(batch)} episodes left for the next call", file=sys.stderr, flush=True)  # fmt: skip
    else:
        print(f"time box: {seconds_left / 60:.1f} min left, fits {n} of {lanes} lanes{basis} "
              f"(~{cell_seconds(cost, n, frames) / 60:.1f} min if none falls)", file=sys.stderr, flush=True)  # fmt: skip
    return n


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


WINDOW_SUGGEST_MARGIN_M = 0.05
"""Room a suggested window leaves beyond the soles' recorded reach [m]."""
REACH_QUANTILE = 0.975
"""A suggested window holds this quantile of the episodes' reach (a lone fall's reach would grow it for all) [-]."""
WINDOW_TURN_SHARE = 0.1
"""A suggested window is a square when at least this fraction of the early exits came from the robot's turn [-]."""


def reach_quantile(rows: list[dict[str, Any]], q: float = REACH_QUANTILE) -> tuple[float, float, float]:
    """The ``q`` quantile over episodes of the soles' reach behind / ahead of / beside the pelvis [m] (NaN: none)."""

    def one(k: str) -> float:
        vals = [float(v) for r in rows if (v := r.get(k)) is not None and math.isfinite(float(v))]
        return float(np.quantile(vals, q)) if vals else math.nan

    return one("sole_behind_m"), one("sole_ahead_m"), one("sole_side_m")


def covering_window(reach: tuple[float, float, float], window: SandWindowCfg, turned: bool) -> SandWindowCfg:
    """The smallest moving window holding ``window`` and the soles' reach (behind, ahead, beside the pelvis) [m].

    Each side grows to the reach plus ``WINDOW_SUGGEST_MARGIN_M`` where the reach passed it, rounded up to 5 cm;
    no side shrinks (the convergence check accepted the window's front and rear clearances, not less). With
    ``turned`` (walks that turned out of it) a window that does not turn becomes a square of the larger side; a
    turning window keeps its shape.
    """

    def up(x: float) -> float:
        return math.ceil(round(x / 0.05, 6)) * 0.05

    behind, ahead, side = reach
    rear = max(0.5 * window.length - window.lead, up(behind + WINDOW_SUGGEST_MARGIN_M))
    front = max(0.5 * window.length + window.lead, up(ahead + WINDOW_SUGGEST_MARGIN_M))
    width = max(window.width, 2.0 * up(side + WINDOW_SUGGEST_MARGIN_M))
    length = rear + front
    if turned and not window.turn_with_robot:
        length = width = max(length, width)
    return replace(window, length=round(length, 3), width=round(width, 3), lead=round(0.5 * (front - rear), 3))


def report_window(rows: list[dict[str, Any]], window: SandWindowCfg) -> None:
    """Say on stderr how far the soles reached against the window, and warn about episodes that left it early."""
    import sys

    reach = [max((r.get(k, math.nan) for r in rows if math.isfinite(r.get(k, math.nan))), default=math.nan)
             for k in ("sole_behind_m", "sole_ahead_m", "sole_side_m")]  # fmt: skip
    if not all(math.isfinite(x) for x in reach):
        return
    if window.moving:
        print(f"sand window: the soles reached {reach[0]:.2f} m behind the pelvis, {reach[1]:.2f} m ahead and "
              f"{reach[2]:.2f} m sideways (largest over {len(rows)} episodes); the window spans "
              f"{0.5 * window.length - window.lead:.2f} m behind, {0.5 * window.length + window.lead:.2f} m ahead and "
              f"{0.5 * window.width:.2f} m sideways ("
              + ("turning with the robot)" if window.turn_with_robot else
                 "along the grid's axes; on circles a square of the larger side)"),
              file=sys.stderr, flush=True)  # fmt: skip
    early = [r for r in rows if r.get("window_exit_early")]
    if early:
        worst = min(early, key=lambda r: r["window_exit_s"])
        turned = sum(bool(r.get("window_exit_turn")) for r in early)
        why = (f"; in {turned} of them the robot had turned and the soles were within the window's reach along its "
               "heading: a window that does not turn (--window-fixed-axes) leaves a drifting walk behind; let it "
               "turn with the robot (the default)") if turned else ""  # fmt: skip
        q = reach_quantile(rows)
        cover = covering_window(q, window, turned >= WINDOW_TURN_SHARE * len(early))
        print(f"warning: in {len(early)} of {len(rows)} episodes a sole that needed sand stood outside its sand window "
              f"more than {WINDOW_EXIT_GRACE_S} s before the episode ended (first at {worst['window_exit_s']:.2f} s, "
              f"{worst['key']}): those walks lost their support to the window, not to the sand. Lengthen the window "
              f"or move it back (--window-length, --window-lead, --window-width){why}. A window holding this run's "
              f"reach ({100 * REACH_QUANTILE:g}th percentile): --window-length {cover.length:g} --window-width {cover.width:g} --window-lead {cover.lead:g}",
              file=sys.stderr, flush=True)  # fmt: skip


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
