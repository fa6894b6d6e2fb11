# SPDX-License-Identifier: Apache-2.0
"""Reward and curriculum arithmetic on hand-computed cases (no simulator)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from gmloco.train.mdp.curriculums import _level_moves, _survival_moves
from gmloco.train.mdp.rewards import (
    _clearance,
    _exp_kernel,
    _lateral_gap_penalty,
    _moving,
    _single_stance_time,
    _wrapped_abs_diff,
)


def test_exp_kernel() -> None:
    """exp(-e / std^2): e = 0.5, std = sqrt(0.5) -> exp(-1) = 0.3679."""
    np.testing.assert_allclose(_exp_kernel(torch.tensor([0.0, 0.5]), math.sqrt(0.5)), [1.0, math.exp(-1.0)], rtol=1e-6)


def test_wrapped_abs_diff_wraps_across_pi() -> None:
    """|wrap(a_R - a_L)|: (0.1, 0.3) -> 0.2; (3.1, -3.1) -> 2 pi - 6.2 = 0.0832 (not 6.2)."""
    angles = torch.tensor([[0.1, 0.3], [3.1, -3.1]])
    np.testing.assert_allclose(_wrapped_abs_diff(angles), [0.2, 2 * math.pi - 6.2], rtol=1e-5)


def test_single_stance_time() -> None:
    """Single stance rewards min(stance time, swing time) up to the threshold; double stance and flight give 0.

    Row 0: left stance 0.3 s, right swing 0.2 s -> 0.2. Row 1: swing 0.8 s vs stance 0.9 s -> clamp 0.5.
    Row 2: both in contact -> 0. Row 3: both in the air -> 0.
    """
    air = torch.tensor([[0.0, 0.2], [0.8, 0.0], [0.0, 0.0], [0.4, 0.3]])
    contact = torch.tensor([[0.3, 0.0], [0.0, 0.9], [0.5, 0.6], [0.0, 0.0]])
    np.testing.assert_allclose(_single_stance_time(air, contact, 0.5), [0.2, 0.5, 0.0, 0.0], rtol=1e-6)


def test_clearance() -> None:
    """Clearance reward exp(-sum (h - 0.1)^2 tanh(2 |v|) / 0.05) on two hand-computed rows.

    Foot at target -> 1; h = 0, |v| = 1 m/s on one foot: 0.01 * tanh(2) / 0.05 = 0.19281 -> exp(-0.19281)
    = 0.82464; a resting foot (v = 0) costs nothing.
    """
    height = torch.tensor([[0.1, 0.0], [0.0, 0.0]])
    speed = torch.tensor([[1.0, 0.0], [1.0, 0.0]])
    expected = [1.0, math.exp(-0.01 * math.tanh(2.0) / 0.05)]
    np.testing.assert_allclose(_clearance(height, speed, 0.1, 0.05, 2.0), expected, rtol=1e-6)


def test_lateral_gap_penalty_in_yaw_frame() -> None:
    """Lateral foot gap penalty, measured in the base yaw frame.

    Feet 0.1 m apart laterally -> penalty 0.2 - 0.1 = 0.1; the same feet seen by a base yawed 90 deg (feet
    apart along world x) are still 0.1 m apart in the base y; 0.3 m apart -> 0.
    """
    feet = torch.tensor(
        [[[0.0, 0.05, 0.0], [0.0, -0.05, 0.0]], [[0.05, 0.0, 0.0], [-0.05, 0.0, 0.0]], [[0, 0.15, 0], [0, -0.15, 0]]]
    )
    c, s = math.cos(math.pi / 4), math.sin(math.pi / 4)  # quaternion (w, x, y, z) of a 90 deg yaw
    quat = torch.tensor([[1.0, 0.0, 0.0, 0.0], [c, 0.0, 0.0, s], [1.0, 0.0, 0.0, 0.0]])
    np.testing.assert_allclose(_lateral_gap_penalty(feet, quat, 0.2), [0.1, 0.1, 0.0], atol=1e-6)


def test_moving_threshold() -> None:
    """|v_xy| + |w_z| > 0.05 counts as a motion command."""
    cmd = torch.tensor([[0.0, 0.0, 0.0], [0.03, 0.04, 0.0], [0.0, 0.0, -0.1]])
    np.testing.assert_array_equal(_moving(cmd, 0.05), [0.0, 0.0, 1.0])


def test_level_moves() -> None:
    """Walked 5 m of 4 needed -> +1; walked 1 m of 10 m commanded -> -1; 3 m of 4 m commanded -> 0."""
    moves = _level_moves(torch.tensor([5.0, 1.0, 3.0]), torch.tensor([20.0, 10.0, 4.0]), 4.0)
    np.testing.assert_array_equal(moves, [1, -1, 0])


def test_survival_moves() -> None:
    """Timed out -> +1; failed -> -1; neither (a reset without an ending) -> 0; a time out wins over a failure."""
    moves = _survival_moves(torch.tensor([True, False, False, True]), torch.tensor([False, True, False, True]))
    np.testing.assert_array_equal(moves, [1, -1, 0, 1])


def test_curriculum_scale_compresses_stages_and_ramps() -> None:
    """``curriculum_scale`` multiplies the command-stage steps and the tracking ramp length."""
    from dataclasses import replace

    from gmloco.train import g1_granular_task
    from gmloco.train.tasks.g1_granular.rewards_cfg import make_curriculum_cfg, make_rewards_cfg

    task = replace(g1_granular_task("rft3d"), curriculum_scale=0.1)
    cur = make_curriculum_cfg(task, make_rewards_cfg(task))
    steps = [stage["step"] for stage in cur["command_vel"].params["velocity_stages"]]
    assert steps == [0, 24_000, 36_000]
    assert cur["ramp_track_lin_vel_xy_exp"].params["num_steps"] == 36_000
    paper = make_curriculum_cfg(g1_granular_task("rft3d"), make_rewards_cfg(task))
    assert paper["ramp_track_yaw_target_exp"].params["num_steps"] == 360_000


def test_clearance_penalty_is_zero_for_still_feet_and_grows_with_the_miss() -> None:
    """The L2 form pays nothing to still feet (unlike the exp reward, which pays them its maximum)."""
    from gmloco.train.mdp.rewards import _clearance, _clearance_error

    height = torch.tensor([[0.0, 0.3]])
    still = torch.zeros(1, 2)
    assert _clearance_error(height, still, 0.1, 2.0).item() == 0.0
    assert _clearance(height, still, 0.1, 0.05, 2.0).item() == 1.0  # the exp form's maximum
    moving = torch.tensor([[10.0, 10.0]])
    miss = _clearance_error(height, moving, 0.1, 2.0).item()
    assert abs(miss - (0.01 + 0.04) * float(torch.tanh(torch.tensor(20.0)))) < 1e-6
    assert _clearance_error(torch.tensor([[0.1, 0.1]]), moving, 0.1, 2.0).item() == 0.0


def test_foot_clearance_form_selects_the_term() -> None:
    """``foot_clearance="penalty"`` (default) uses foot_clearance_l2 with weight -2; "reward" the exp form."""
    from dataclasses import replace

    from gmloco.train import g1_granular_task
    from gmloco.train.tasks.g1_granular.rewards_cfg import make_rewards_cfg

    task = g1_granular_task("rft3d")
    rewards = make_rewards_cfg(task)
    assert rewards["foot_clearance_l2"].weight == -2.0 and "foot_clearance" not in rewards
    rewards = make_rewards_cfg(replace(task, foot_clearance="reward"))
    assert rewards["foot_clearance"].weight == 5.0 and "foot_clearance_l2" not in rewards
    rewards = make_rewards_cfg(replace(task, foot_clearance="touchdown"))
    assert rewards["foot_clearance_l2"].weight == -2.0 and rewards["swing_height_at_touchdown"].weight == 100.0
    assert "swing_height_at_touchdown" not in make_rewards_cfg(task)


def test_swing_height_is_paid_once_per_touchdown_clipped_and_only_when_moving() -> None:
    """Foot 0 lands after a 20 cm lift (paid the 12 cm cap), foot 1 is in the air; a still command pays nothing."""
    from types import SimpleNamespace

    from gmloco.train.mdp.rewards import swing_height_at_touchdown

    feet = SimpleNamespace(
        first_contact=torch.tensor([[True, False], [True, True]]),
        last_swing_lift=torch.tensor([[0.20, 0.05], [0.05, 0.07]]),
        last_swing_apex=torch.tensor([[0.04, 0.01], [-0.02, 0.03]]),
    )
    feet.update = lambda: feet
    commands = torch.tensor([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    env = SimpleNamespace(
        sand=SimpleNamespace(feet=feet), command_manager=SimpleNamespace(get_command=lambda name: commands)
    )
    lift = swing_height_at_touchdown(env, 0.12, "twist")  # type: ignore[arg-type]
    np.testing.assert_allclose(lift.numpy(), [0.12, 0.12], atol=1e-7)
    apex = swing_height_at_touchdown(env, 0.12, "twist", relative=False)  # type: ignore[arg-type]
    np.testing.assert_allclose(apex.numpy(), [0.04, 0.03], atol=1e-7)  # a sunk apex pays 0, not a penalty
    commands.zero_()
    assert swing_height_at_touchdown(env, 0.12, "twist").abs().sum().item() == 0.0


def test_sand_floor_levels_survival_rule(monkeypatch: pytest.MonkeyPatch) -> None:
    """``promotion="survival"``: timed-out envs go one level deeper, failed ones one shallower, clamped to the range."""
    from dataclasses import replace
    from types import SimpleNamespace

    from gmloco.train.config import FloorPromotion, SandFloorCfg, SandTerrainCfg
    from gmloco.train.mdp import curriculums

    floor = replace(SandFloorCfg(), promotion=FloorPromotion.survival, num_levels=3)
    sand = SimpleNamespace(
        task=SimpleNamespace(terrain=SandTerrainCfg(floor=floor)),
        floor_level=torch.tensor([0, 1, 2, 0, 1]),
        floor_depth=torch.zeros(5),
    )
    monkeypatch.setattr(curriculums, "get_sand", lambda env: sand)
    terms = SimpleNamespace(
        time_outs=torch.tensor([True, True, True, False, False]),
        terminated=torch.tensor([False, False, False, True, False]),
    )
    env = SimpleNamespace(common_step_counter=10, termination_manager=terms)
    out = curriculums.sand_floor_levels(env, torch.tensor([0, 1, 2, 3]), command_name="twist")  # type: ignore[arg-type]
    np.testing.assert_array_equal(sand.floor_level, [1, 2, 2, 0, 1])  # env 4 was not reset
    assert float(out["max"]) == 2.0
