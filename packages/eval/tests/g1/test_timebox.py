# SPDX-License-Identifier: Apache-2.0
"""The time box: minutes a cell has left, and the prior cost of a cell before it is built."""

from __future__ import annotations

from dataclasses import replace

import pytest

from gmloco.eval.g1.config import G1EvalCfg, episode_specs
from gmloco.eval.g1.timebox import cell_minutes_left


def test_minutes_left_counts_waves_of_lanes() -> None:
    """2 lanes with 10 and 40 steps left, 3 queued episodes of 100 steps, 4 frames per step at 2 frames/s.

    Lane A: 10 -> 110 -> 210; lane B: 40 -> 140; the last ends at step 210 = 840 frames = 420 s = 7 min.
    """
    assert cell_minutes_left([10, 40], 3, 100, 4, 2.0) == pytest.approx(7.0)
    assert cell_minutes_left([], 5, 100, 4, 2.0) == 0.0 and cell_minutes_left([1], 0, 100, 4, 0.0) == 0.0


def test_the_prior_prices_the_cell_build_cell_scene_builds() -> None:
    """The prior counts the batch's window as the scene solves it: the terrain's depth, one window for every walk."""
    from gmloco.eval.g1.cost import PRIOR_FRAME_S_AT_ZERO, PRIOR_FRAME_S_PER_MILLION
    from gmloco.eval.g1.timebox import cell_prior_cost

    cfg = replace(G1EvalCfg(), robots_per_batch=25, scenarios=("straight", "circle"))
    specs = episode_specs(cfg)
    straight = [s for s in specs if s.scenario == "straight"]
    circle = [s for s in specs if s.scenario == "circle"]
    per_lane = 94 * 40 * 20  # 1.4 x 0.6 m at 1.5 cm spacing, 30 cm deep
    cost = cell_prior_cost(straight, cfg)
    assert cost.lanes == 25
    assert cost.frame_s == pytest.approx(PRIOR_FRAME_S_AT_ZERO + PRIOR_FRAME_S_PER_MILLION * 25 * per_lane / 1e6)
    assert cell_prior_cost(circle, cfg).frame_s == cost.frame_s  # the turning window serves the circle as it is
    fixed = replace(cfg, window=replace(cfg.window, turn_with_robot=False))
    assert cell_prior_cost(circle, fixed).frame_s > cost.frame_s  # a window on the grid's axes: 94 x 94 on a circle
