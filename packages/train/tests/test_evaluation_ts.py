# SPDX-License-Identifier: Apache-2.0
"""Pieces of the teacher-student evaluation that need no env: swing apexes, cells, JSON cleaning."""

from __future__ import annotations

import math

import numpy as np

from gmloco.train.evaluation_ts import TsEvalCfg, _cells, finite_json, swing_apexes


def test_swing_apexes_hand_computed() -> None:
    """Two swings (steps 2-5 and 8-11) end in touchdowns; apexes at their highest steps 3 and 10.

    contact: T T F F F F T T F F F F T ; a 1-step flicker at 13 and the swing cut by death at 15 are not counted.
    """
    contact = np.array([1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0], dtype=bool)
    height = np.array([0, 0, 0.05, 0.12, 0.08, 0.02, 0, 0, 0.03, 0.1, 0.16, 0.04, 0, 0.3, 0, 0.2, 0.5, 0.1])
    alive = np.ones(contact.size, dtype=bool)
    alive[16:] = False
    assert swing_apexes(height, contact, alive) == [3, 10]
    assert swing_apexes(height, contact, alive, min_steps=5) == []


def test_cells_hold_the_held_out_grid_then_the_presets() -> None:
    """3 x 2 held-out materials and 2 presets, x 2 speeds x 3 repeats; held-out cells lie inside the region."""
    cfg = TsEvalCfg(held_out_grid=(3, 2), presets=("basalt", "poppy_seed"), speeds=(0.5, 1.0), repeats=3)
    cells = _cells(cfg)
    assert len(cells) == (6 + 2) * 2 * 3
    held = [c for c in cells if c.group == "held_out"]
    assert len(held) == 36 and all(cfg.held_out.contains(np.asarray(c.rho_c), np.asarray(c.mu_int)) for c in held)
    assert [c.label for c in cells[36:]] == ["basalt"] * 6 + ["poppy_seed"] * 6
    assert {c.speed for c in cells} == {0.5, 1.0}


def test_finite_json_replaces_non_finite_floats() -> None:
    """NaN and inf become None at any depth (JSON has neither)."""
    out = finite_json({"a": math.nan, "b": [1.0, math.inf, {"c": -math.inf}], "d": "NaN"})
    assert out == {"a": None, "b": [1.0, None, {"c": None}], "d": "NaN"}
