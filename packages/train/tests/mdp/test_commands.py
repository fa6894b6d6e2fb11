# SPDX-License-Identifier: Apache-2.0
"""YawTargetVelocityCommand on a stand-in env: the yaw target integrates w_z, snaps, re-snaps and corrects w_z."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest
import torch
from mjlab.tasks.velocity.mdp import UniformVelocityCommandCfg

from gmloco.train.mdp.commands import YawTargetVelocityCommand, YawTargetVelocityCommandCfg, corrected_yaw_rate
from gmloco.train.mdp.rewards import track_yaw_target_exp

DT = 0.02
"""Policy step [s] (50 Hz)."""


class _Robot(SimpleNamespace):
    """Stand-in robot: a heading the test sets, zero body velocities."""

    def __init__(self, n: int) -> None:
        zeros3 = torch.zeros(n, 3)
        super().__init__(
            data=SimpleNamespace(heading_w=torch.zeros(n), root_link_lin_vel_b=zeros3, root_link_ang_vel_b=zeros3)
        )


def _term(n: int = 2, stiffness: float = 1.0) -> tuple[YawTargetVelocityCommand, _Robot]:
    """A command term over ``n`` stand-in envs, commands never resampled."""
    robot = _Robot(n)
    env = SimpleNamespace(num_envs=n, device="cpu", step_dt=DT, scene={"robot": robot})
    cfg = YawTargetVelocityCommandCfg(
        entity_name="robot",
        resampling_time_range=(1e9, 1e9),
        rel_heading_envs=0.0,
        heading_stiffness=stiffness,
        ranges=UniformVelocityCommandCfg.Ranges(lin_vel_x=(0.0, 1.0), lin_vel_y=(0.0, 0.0), ang_vel_z=(-1.0, 1.0)),
    )
    term = YawTargetVelocityCommand(cfg, env)  # type: ignore[arg-type]
    ids = torch.arange(n)
    term.reset(ids)
    term.set_twist(torch.tensor([[1.0, 0.0, 0.0]] * n), ids)
    term.compute(0.0, ids)  # the reset path: the target snaps to the heading
    return term, robot


def test_target_snaps_to_the_heading_at_reset_and_holds_under_a_straight_command() -> None:
    """After a reset the target is the current heading; with w_z = 0 it stays, and a turned robot is steered back."""
    term, robot = _term()
    robot.data.heading_w[:] = torch.tensor([0.3, -0.3])
    term.reset(torch.tensor([1]))  # env 1 starts a new episode at -0.3 rad
    term.set_twist(torch.tensor([[1.0, 0.0, 0.0]]), torch.tensor([1]))
    term.compute(DT)
    torch.testing.assert_close(term.yaw_target, torch.tensor([0.0, -0.3]))
    # env 0 turned 0.3 rad left of its target: observed w_z = 0 + 1.0 * (0 - 0.3) turns it back right
    torch.testing.assert_close(term.command[:, 2], torch.tensor([-0.3, 0.0]))
    torch.testing.assert_close(term.command[:, :2], torch.tensor([[1.0, 0.0], [1.0, 0.0]]))


def test_target_integrates_the_commanded_yaw_rate() -> None:
    """Holding w_z = 0.5 rad/s for 50 steps of 0.02 s moves the target by 0.5 rad; a robot that keeps up sees 0.5."""
    term, robot = _term(n=1)
    term.set_twist(torch.tensor([[0.5, 0.0, 0.5]]))
    for _ in range(50):
        term.compute(DT)
        robot.data.heading_w += 0.5 * DT  # the robot turns at the commanded rate
    torch.testing.assert_close(term.yaw_target, torch.tensor([0.5]), atol=1e-5, rtol=0)
    torch.testing.assert_close(term.command[:, 2], torch.tensor([0.5]), atol=1e-4, rtol=0)


def test_robot_that_does_not_turn_sees_a_growing_yaw_rate_command_until_the_target_resnaps() -> None:
    """A robot that never turns: w_z_obs = 0.5 + e, clipped at 1 rad/s; past pi/2 of error the target re-snaps."""
    term, _ = _term(n=1)
    term.set_twist(torch.tensor([[0.0, 0.0, 0.5]]))
    seen = []
    for _ in range(200):  # 4 s: the target runs 2 rad ahead without re-snapping
        term.compute(DT)
        seen.append((float(term.yaw_error), float(term.command[0, 2])))
    errors = [e for e, _ in seen]
    assert max(errors) <= math.pi / 2 + 1e-6
    assert min(errors[100:]) < 0.1  # re-snapped once the error passed pi/2 (after ~3.1 s)
    e, wz = seen[20]
    assert e == pytest.approx(0.5 * 20 * DT, abs=1e-5) and wz == pytest.approx(min(0.5 + e, 1.0), abs=1e-5)


def test_zero_stiffness_observes_the_raw_command_and_the_clip_holds() -> None:
    """K = 0 leaves w_z as commanded; the correction never leaves the command range."""
    term, robot = _term(stiffness=0.0)
    robot.data.heading_w[:] = 0.4
    term.compute(DT)
    torch.testing.assert_close(term.command[:, 2], torch.zeros(2))
    out = corrected_yaw_rate(torch.tensor([0.9, -0.9]), torch.tensor([1.0, -1.0]), 2.0, (-1.0, 1.0))
    torch.testing.assert_close(out, torch.tensor([1.0, -1.0]))


def test_track_yaw_target_reward_is_one_on_target_and_falls_with_the_error() -> None:
    """exp(-e^2 / std^2): 1 at e = 0, exp(-1) at e = std."""
    term, robot = _term()
    robot.data.heading_w[:] = torch.tensor([0.0, 0.5])
    term.compute(DT)
    env = SimpleNamespace(command_manager=SimpleNamespace(get_term=lambda name: term))
    reward = track_yaw_target_exp(env, std=0.5, command_name="twist")  # type: ignore[arg-type]
    torch.testing.assert_close(reward, torch.tensor([1.0, math.exp(-1.0)]))
