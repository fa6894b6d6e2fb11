# SPDX-License-Identifier: Apache-2.0
"""The sand window and lane spacing of a cell, by scenario and window kind."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from gmloco.eval.g1.config import EpisodeSpec, G1EvalCfg, Scenario


def test_one_turning_window_serves_straight_and_circle() -> None:
    """The default window turns: the circle keeps it, lanes spaced by its diagonal plus twice its lead (any heading).

    1.4 x 0.6 m, lead 0.2 m: hypot = 1.5232 m, + 0.4 = 1.9232 m; the circle adds its 4 m diameter.
    """
    from gmloco.eval.g1.lanes import window_and_lanes

    cfg = G1EvalCfg()
    straight, lane_s = window_and_lanes([EpisodeSpec("dry_sand", Scenario.straight, 1.0, 0)], cfg)
    circle, lane_c = window_and_lanes([EpisodeSpec("dry_sand", Scenario.circle, 1.0, 0)], cfg)
    assert straight == circle == cfg.window and cfg.window.turn_with_robot
    span = math.hypot(1.4, 0.6) + 0.4
    assert lane_s == pytest.approx(span + cfg.lane_gap)
    assert lane_c == pytest.approx(span + 2.0 * cfg.circle_radius + cfg.lane_gap)


def test_a_window_on_the_grid_axes_becomes_a_square_on_a_circle() -> None:
    """A window that does not turn: on a circle it is max(length, width) square; straight it is as set."""
    from gmloco.eval.g1.lanes import window_and_lanes

    cfg = replace(G1EvalCfg(), window=replace(G1EvalCfg().window, turn_with_robot=False))
    straight, lane_s = window_and_lanes([EpisodeSpec("dry_sand", Scenario.straight, 1.0, 0)], cfg)
    circle, lane_c = window_and_lanes([EpisodeSpec("dry_sand", Scenario.circle, 1.0, 0)], cfg)
    assert (straight.length, straight.width) == (cfg.window.length, cfg.window.width)
    side = max(cfg.window.length, cfg.window.width)
    assert (circle.length, circle.width, circle.lead) == (side, side, cfg.window.lead)
    assert lane_c == side + 2.0 * cfg.circle_radius + cfg.lane_gap and lane_s == cfg.window.width + cfg.lane_gap
