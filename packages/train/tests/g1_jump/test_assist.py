# SPDX-License-Identifier: Apache-2.0
"""Assistive base wrench: zero at scale 0, the PD law at scale 1, clipped, and annealed by tracking success."""

from __future__ import annotations

from dataclasses import replace

import pytest
import torch

from gmloco.train.tasks.g1_jump.assist import AssistState, assist_wrench, judged_episodes
from gmloco.train.tasks.g1_jump.config import JumpAssistCfg

IDENTITY = torch.tensor([[1.0, 0.0, 0.0, 0.0]])
"""Upright base orientation (w, x, y, z)."""


def _wrench(cfg: JumpAssistCfg, scale: float, dz: float, yaw: float = 0.0) -> tuple[torch.Tensor, torch.Tensor]:
    """Wrench with the base ``dz`` [m] below the reference and the reference yawed by ``yaw`` [rad]."""
    zero = torch.zeros(1, 3)
    ref_quat = torch.tensor([[torch.cos(torch.tensor(yaw / 2)), 0.0, 0.0, torch.sin(torch.tensor(yaw / 2))]])
    pos = torch.tensor([[0.0, 0.0, 0.7 - dz]])
    return assist_wrench(cfg, scale, pos, IDENTITY, zero, zero, torch.tensor([[0.0, 0.0, 0.7]]), ref_quat, zero, zero)


def test_zero_scale_gives_zero_wrench() -> None:
    """At s = 0 the wrench vanishes whatever the tracking error."""
    force, torque = _wrench(JumpAssistCfg(), 0.0, dz=0.2, yaw=0.5)
    assert torch.count_nonzero(force) == 0 and torch.count_nonzero(torque) == 0


def test_full_scale_is_the_pd_law() -> None:
    """At s = 1, base 5 cm low, reference yawed 0.1 rad: F_z = kp * 0.05 = 100 N, T_z = kp_r * 0.1 = 40 N m."""
    cfg = JumpAssistCfg()  # kp_pos 2000 N/m, kp_rot 400 N m/rad
    force, torque = _wrench(cfg, 1.0, dz=0.05, yaw=0.1)
    torch.testing.assert_close(force, torch.tensor([[0.0, 0.0, 100.0]]))
    torch.testing.assert_close(torque, torch.tensor([[0.0, 0.0, 40.0]]), atol=1e-4, rtol=1e-5)
    half, _ = _wrench(cfg, 0.5, dz=0.05)
    torch.testing.assert_close(half, 0.5 * force)


def test_wrench_is_clipped() -> None:
    """A 1 m error asks for 2000 N; the cap keeps |F| at max_force in the same direction."""
    force, _ = _wrench(JumpAssistCfg(max_force=650.0), 1.0, dz=1.0)
    torch.testing.assert_close(force, torch.tensor([[0.0, 0.0, 650.0]]))


def test_scale_anneals_on_success_and_only_on_success() -> None:
    """With every episode a success the scale drops one step per judged batch; with failures it stays."""
    cfg = JumpAssistCfg(scale_step=0.25, success_threshold=0.8, success_ema=1.0, min_episodes_per_env=1.0)
    state = AssistState(scale=1.0)
    state.update(cfg, successes=2, episodes=4, num_envs=4)  # 50 % success: no change
    assert state.scale == 1.0 and state.success_rate == pytest.approx(0.5)
    scales = []
    for _ in range(5):
        state.update(cfg, successes=4, episodes=4, num_envs=4)
        scales.append(state.scale)
    assert scales == [0.75, 0.5, 0.25, 0.0, 0.0]


def test_scale_waits_for_enough_episodes() -> None:
    """Two episodes per env (8 at 4 envs) must finish between two steps."""
    cfg = JumpAssistCfg(scale_step=0.1, success_ema=1.0, min_episodes_per_env=2.0)
    state = AssistState(scale=1.0)
    state.update(cfg, successes=4, episodes=4, num_envs=4)
    assert state.scale == 1.0
    state.update(cfg, successes=4, episodes=4, num_envs=4)
    assert state.scale == pytest.approx(0.9) and state.episodes_since_change == 0


def test_disabled_assist_never_changes() -> None:
    """enabled=False leaves the state alone."""
    state = AssistState(scale=0.0)
    state.update(replace(JumpAssistCfg(), enabled=False), successes=10, episodes=10, num_envs=1)
    assert state.scale == 0.0 and state.success_rate == 0.0


def test_state_round_trips_through_a_checkpoint_dict() -> None:
    """state_dict / load_state_dict restore scale, success rate and the episode count."""
    state = AssistState(scale=0.42, success_rate=0.9, episodes_since_change=17)
    other = AssistState(scale=1.0)
    other.load_state_dict(state.state_dict())
    assert other == state


def test_only_episodes_with_the_jump_are_judged() -> None:
    """Of 4 finished episodes, 3 started before the 1.02 s take-off; 2 of those timed out (succeeded)."""
    timed_out = torch.tensor([True, False, True, True])
    start = torch.tensor([0.0, 0.5, 1.0, 1.5])  # the last one started after the take-off
    assert judged_episodes(timed_out, start, 1.02) == (2, 3)
