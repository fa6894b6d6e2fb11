# SPDX-License-Identifier: Apache-2.0
"""Teacher-student evaluation: swing apexes, cells, JSON cleaning, per-material stats; the teacher-acting walk."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from gmloco.train.evaluation_ts import (
    TsEvalCfg,
    _adaptation_stats,
    _cells,
    evaluate_teacher_student,
    finite_json,
    pinned_walk,
    swing_apexes,
)

TEACHER_CHECKPOINT = Path(__file__).parents[3] / "artifacts" / "gm_loco_teacher_clr50" / "checkpoint.pt"
"""Committed ``TeacherPPO`` checkpoint (the env-building test skips without it)."""
ADAPTATION_KEYS = {
    "material",
    "steps",
    "falls",
    "swings",
    "swing_apex_mean_m",
    "swing_apex_std_m",
    "swing_apex_p90_m",
    "swing_lift_mean_m",
    "v_forward",
    "eta_true",
    "eta_teacher",
}
"""Keys of a per-material row of the teacher-acting walk."""


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


def test_adaptation_stats_assign_apexes_and_falls_to_the_material_under_the_robot() -> None:
    """Swings, lifts and falls land on the material under the robot; nothing on material 2.

    Env 0: a swing on material 0 (apex 0.08 m, lowest point before it 0.0 m), one on material 1 (apex 0.12 m,
    lowest point since the first apex -0.02 m); env 1: the same, but it fails at step 8 on material 1, so its second
    swing never lands.

    No ``eta_student`` trace (teacher acting): the rows carry no ``eta_student`` key.
    """
    cfg = TsEvalCfg(actor="teacher")
    contact = np.array([1, 0, 0, 0, 1, 1, 0, 0, 0, 1], dtype=float)
    height = np.array([0, 0.03, 0.08, 0.02, -0.02, 0, 0.05, 0.12, 0.04, 0])
    material = np.array([0, 0, 0, 0, 0, 1, 1, 1, 1, 1], dtype=float)
    both = lambda v: np.stack([v, v], axis=1)  # noqa: E731
    raw = {
        "s": both(np.linspace(0.0, 1.0, 10)),
        "material": both(material),
        "eta_true": both(0.5 - 0.4 * material),
        "eta_teacher": both(0.45 - 0.4 * material),
        "v_forward": both(np.full(10, 0.9)),
        "left_height": both(height),
        "left_contact": both(contact),
        "alive": np.stack([np.ones(10), (np.arange(10) < 8).astype(float)], axis=1),
    }
    rows = _adaptation_stats(cfg, raw)
    assert [r["material"] for r in rows] == list(cfg.adaptation_materials)
    assert [r["swings"] for r in rows] == [2, 1, 0] and [r["falls"] for r in rows] == [0, 1, 0]
    assert [r["steps"] for r in rows] == [10, 8, 0]
    assert rows[0]["swing_apex_mean_m"] == pytest.approx(0.08) and rows[1]["swing_apex_mean_m"] == pytest.approx(0.12)
    assert rows[0]["swing_lift_mean_m"] == pytest.approx(0.08) and rows[1]["swing_lift_mean_m"] == pytest.approx(0.14)
    assert rows[0]["swing_apex_std_m"] == 0.0 and rows[2]["swing_apex_mean_m"] is None
    assert rows[1]["eta_true"] == pytest.approx(0.1) and rows[1]["v_forward"] == pytest.approx(0.9)
    assert set(rows[0]) == ADAPTATION_KEYS


@pytest.mark.skipif(not TEACHER_CHECKPOINT.exists(), reason=f"{TEACHER_CHECKPOINT} absent")
def test_teacher_acting_walk_returns_per_material_stats(device: str, tmp_path: Path) -> None:
    """The committed teacher walks the course for 10 steps on 2 envs; summary, figure and trace are written."""
    cfg = TsEvalCfg(
        actor="teacher",
        teacher_checkpoint=str(TEACHER_CHECKPOINT),
        adaptation_envs=2,
        adaptation_duration_s=0.2,
        device=device,
        out_dir=str(tmp_path),
    )
    summary = evaluate_teacher_student(cfg)
    assert summary["actor"] == "teacher" and 0 <= summary["adaptation_survived"] <= 2
    rows = summary["adaptation"]
    assert [r["material"] for r in rows] == list(cfg.adaptation_materials)
    assert all(set(r) == ADAPTATION_KEYS for r in rows)
    assert sum(r["steps"] for r in rows) == 2 * 10 and rows[0]["steps"] > 0
    assert 0.0 <= rows[0]["eta_teacher"] <= 1.0 and rows[0]["eta_true"] > 0.0
    assert {p.name for p in tmp_path.iterdir()} == {"summary.json", "adaptation.png", "adaptation_env0.json"}


@pytest.mark.skipif(not TEACHER_CHECKPOINT.exists(), reason=f"{TEACHER_CHECKPOINT} absent")
def test_pinned_walk_returns_one_pelvis_trace_per_env(device: str) -> None:
    """Two envs (dry sand / basalt, two commands) for 5 steps: [T, W] traces, unit quaternions, all alive at first."""
    cfg = TsEvalCfg(actor="teacher", teacher_checkpoint=str(TEACHER_CHECKPOINT), device=device)
    with pytest.raises(ValueError, match="one each per env"):
        pinned_walk(cfg, ["dry_sand"], [(1.0, 0.0, 0.0), (1.0, 0.0, 0.5)], 0.1)
    walk = pinned_walk(cfg, ["dry_sand", "basalt"], [(1.0, 0.0, 0.0), (1.0, 0.0, 0.5)], 0.1)
    assert walk["dt"] == pytest.approx(0.02)
    assert walk["quat_wxyz"].shape == (5, 2, 4) and walk["xy"].shape == (5, 2, 2) and walk["wz"].shape == (5, 2)
    np.testing.assert_allclose(np.linalg.norm(walk["quat_wxyz"], axis=-1), 1.0, atol=1e-5)
    assert walk["alive"][0].all() and walk["wall_s"] > 0.0
    # the pinned materials' true eta (basalt stiffer than dry sand) and the teacher's decoded one, per step and env
    assert walk["eta_true"].shape == walk["eta_teacher"].shape == (5, 2) and "eta_student" not in walk
    assert walk["eta_true"][0, 1] > walk["eta_true"][0, 0] and np.all(
        (walk["eta_teacher"] >= 0) & (walk["eta_teacher"] <= 1)
    )
