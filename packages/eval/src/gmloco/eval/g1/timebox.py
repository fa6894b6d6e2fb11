# SPDX-License-Identifier: Apache-2.0
"""The time box around the episode loop: which walks can still end before the deadline, and how long a cell has left.

The cost of a cell comes from the GPU cost model (:mod:`gmloco.eval.g1.cost`: measured, or the H200 prior before
the cell is built); :func:`gmloco.eval.g1.run.run` sizes each cell with :func:`lanes_in_time_box` and
:func:`gmloco.eval.g1.cell.run_cell` starts a freed lane's next walk only when :func:`walk_fits`.
"""

from __future__ import annotations

import math
import time

from gmloco.eval.g1.config import EpisodeSpec, G1EvalCfg
from gmloco.eval.g1.cost import CellCost, cell_seconds, fit_lanes, prior_cost
from gmloco.eval.g1.lanes import cell_sand

__all__ = ["cell_minutes_left", "cell_prior_cost", "lanes_in_time_box", "walk_fits"]


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


def walk_fits(cost: CellCost | None, frames: int, deadline: float | None) -> bool:
    """Whether a walk of ``frames`` frames started now ends before ``deadline`` at ``cost`` (True: not measured)."""
    if cost is None or deadline is None:
        return True
    return time.perf_counter() + cell_seconds(cost, cost.lanes, frames, build=False) <= deadline


def cell_prior_cost(batch: list[EpisodeSpec], cfg: G1EvalCfg) -> CellCost:
    """``g1_eval_fit.prior_cost`` of ``batch``'s cell as ``build_cell_scene`` would build it."""
    per_lane = cell_sand(batch, cfg)[3]
    return prior_cost(per_lane, min(cfg.robots_per_batch, len(batch)), cfg.solver.max_iterations)


def lanes_in_time_box(
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
