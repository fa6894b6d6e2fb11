# SPDX-License-Identifier: Apache-2.0
"""A cell's sand: each lane's window, the lanes' spacing and the particles a lane puts in the MPM solve."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from gmloco.eval.g1.config import EpisodeSpec, G1EvalCfg, command
from gmloco.eval.metrics.locomotion import circular_path
from gmloco.eval.mpm.window import SandWindowCfg

__all__ = ["cell_sand", "window_and_lanes", "window_particles"]


def window_and_lanes(batch: list[EpisodeSpec], cfg: G1EvalCfg) -> tuple[SandWindowCfg, float]:
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


def cell_sand(specs: list[EpisodeSpec], cfg: G1EvalCfg) -> tuple[Any, SandWindowCfg, float, int]:
    """A cell's terrain, sand window, lane spacing [m] and particles per lane, as ``build_cell_scene`` builds it."""
    from gmloco.eval.mpm.window_terrain import terrain_cfg

    terrain = terrain_cfg(specs[0].terrain, depth=cfg.bed_depth)
    window, lane = window_and_lanes(specs, cfg)
    return terrain, window, lane, window_particles(window, terrain.depth, cfg.solver.voxel_size)


def window_particles(window: SandWindowCfg, depth: float, voxel: float) -> int:
    """Particles of one robot's window in the MPM solve: nx ny columns of nz (as :class:`SandWindow` sizes it).

    A turning window holds nx ny columns to within its perimeter's cells (``window_slots`` reserves up to
    ``sqrt(2) (nx + ny) + 2`` more slots for its worst heading); its free slots are parked, out of the solve.
    """
    h = voxel / window.particles_per_voxel
    nx, ny = max(1, math.ceil(window.length / h)), max(1, math.ceil(window.width / h))
    return nx * ny * max(1, round(depth / h))
