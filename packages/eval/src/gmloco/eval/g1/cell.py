# SPDX-License-Identifier: Apache-2.0
"""The episode loop of one (terrain, scenario) cell: robots in lanes of one MPM solver, refilled as episodes end.

The deadline checks inside the loop ask :mod:`gmloco.eval.g1.timebox` (and the GPU cost model behind it) whether a
walk can still end; the physics is :class:`gmloco.eval.g1.scene.G1MpmScene`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np

from gmloco.eval.g1.config import EpisodeSpec, G1EvalCfg, command
from gmloco.eval.g1.cost import CellCost, cell_seconds
from gmloco.eval.g1.lanes import cell_sand
from gmloco.eval.g1.policy import load_policy
from gmloco.eval.g1.timebox import cell_minutes_left, walk_fits
from gmloco.eval.metrics.locomotion import FailureCfg, quat_wxyz_to_roll_pitch_yaw
from gmloco.eval.mpm.box_scene import MpmSolverCfg

__all__ = ["CellOutcome", "build_cell_scene", "check_grid_capacity", "lane_failed", "run_cell"]


def lane_failed(q: np.ndarray, surface_z: float, failure: FailureCfg) -> bool:
    """The paper's fall rule on one pelvis pose ``q`` = (p, q_xyzw): too low above the sand, or tilted too far."""
    roll, pitch, _ = quat_wxyz_to_roll_pitch_yaw(np.array([[q[6], q[3], q[4], q[5]]]))[0]
    return bool(q[2] - surface_z < failure.min_base_height or max(abs(roll), abs(pitch)) > failure.max_tilt)


def build_cell_scene(specs: list[EpisodeSpec], cfg: G1EvalCfg, policy: Any) -> tuple[Any, Any, MpmSolverCfg]:
    """The captured ``G1MpmScene`` of a cell's first ``robots_per_batch`` episodes, its terrain and solver cfg.

    One lane per robot, each commanded as its episode; the active-cell capacity is sized from the windows
    (``cell_capacity_factor``); ``policy`` is reloaded for the lane count if it was built for another.
    """
    from gmloco.eval.g1.scene import G1MpmScene
    from gmloco.eval.g1.scene_cfg import G1MpmSceneCfg

    n = min(cfg.robots_per_batch, len(specs))
    terrain, window, lane, per_lane = cell_sand(specs, cfg)
    solver = cfg.solver
    if cfg.cell_capacity_factor > 0 and solver.grid_type != "dense":
        per_cell = window.particles_per_voxel**3
        est = per_lane * n
        solver = replace(solver, max_active_cell_count=int(cfg.cell_capacity_factor * est / per_cell) + 64)
    scene_cfg = G1MpmSceneCfg(terrain=terrain, window=window, num_robots=n, lane_spacing=lane, solver=solver,
                              commands=tuple(command(s, cfg) for s in specs[:n]),
                              seed=cfg.seed * 100_003 + specs[0].index, device=cfg.device,
                              wrench_frames=cfg.wrench_frames)  # fmt: skip
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
                if queue and walk_fits(cost, steps * k, deadline):
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
    from gmloco.eval.g1.scene_cfg import LOG_FIELDS
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
