# SPDX-License-Identifier: Apache-2.0
"""The jump env: phase observation, reference state initialization, tracking rewards, assistive wrench."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import replace
from typing import Any

import pytest
import torch

from gmloco.train.tasks.g1_jump import mdp
from gmloco.train.tasks.g1_jump.assist import assist_wrench, get_assist
from gmloco.train.tasks.g1_jump.command import get_jump
from gmloco.train.tasks.g1_jump.config import g1_jump_task

NUM_ENVS = 2
"""Envs of the module's env."""
KERNELS = (
    ("track_joint_pos_exp", 0.25),
    ("track_joint_vel_exp", 2.0),
    ("track_base_pos_exp", 0.1),
    ("track_base_ori_exp", 0.3),
    ("track_base_lin_vel_exp", 0.5),
    ("track_base_ang_vel_exp", 1.5),
    ("track_feet_pos_exp", 0.06),
)
"""Tracking reward functions and their stds."""


@pytest.fixture(scope="module")
def env(device: str) -> Iterator[Any]:
    """A 2-env jump env on rigid ground, starting at the first frame (no RSI)."""
    from mjlab.envs import ManagerBasedRlEnv

    from gmloco.train.tasks.g1_jump.env_cfgs import make_g1_jump_env_cfg

    task = replace(g1_jump_task("rigid"), rsi_probability=0.0)
    cfg = make_g1_jump_env_cfg(task, NUM_ENVS)
    cfg.seed = 0
    built = ManagerBasedRlEnv(cfg=cfg, device=device)
    yield built
    built.close()


def _place_on_reference(env: Any, t: float) -> None:
    """Put every env at motion time ``t`` [s] in the reference state and refresh the kinematics."""
    jump = get_jump(env)
    jump.time[:] = t
    jump._write_reference_state(torch.arange(env.num_envs, device=env.device))
    env.sim.forward()


def test_phase_observation_is_sin_cos_of_pi_phase(env: Any) -> None:
    """After a reset at t = 0 and 10 steps, the phase term is (sin, cos)(pi * 0.2 s / T)."""
    env.reset()
    for _ in range(10):
        env.step(torch.zeros(env.num_envs, env.action_manager.total_action_dim, device=env.device))
    jump = get_jump(env)
    angle = math.pi * 10 * env.step_dt / jump.ref.duration
    expected = torch.tensor([[math.sin(angle), math.cos(angle)]] * env.num_envs)
    torch.testing.assert_close(mdp.jump_phase(env).cpu(), expected, atol=1e-5, rtol=0.0)


def test_tracking_rewards_peak_at_the_reference(env: Any) -> None:
    """On the reference (mid-flight, t = 1.1 s) every kernel is 1; a 0.3 rad joint offset lowers the joint term."""
    _place_on_reference(env, 1.1)
    for name, std in KERNELS:
        value = getattr(mdp, name)(env, std=std)
        # float32 storage of the reference: ~1e-6 rad / m errors give kernels within 1e-4 of 1
        torch.testing.assert_close(value.cpu(), torch.ones(env.num_envs), atol=1e-4, rtol=0.0, msg=name)
    robot = env.scene["robot"]
    joint_pos = robot.data.joint_pos.clone()
    joint_pos[1] += 0.3
    robot.write_joint_state_to_sim(joint_pos, robot.data.joint_vel.clone())
    env.sim.forward()
    value = mdp.track_joint_pos_exp(env, std=0.25)
    # exp(-0.3^2 / 0.25^2) = exp(-1.44) = 0.2369 for the offset env
    torch.testing.assert_close(value.cpu(), torch.tensor([1.0, math.exp(-1.44)]), atol=1e-4, rtol=0.0)
    assert mdp.track_feet_pos_exp(env, std=0.06)[1] < 1.0 - 1e-3


def _pelvis_wrench(env: Any) -> torch.Tensor:
    """Pelvis ``xfrc_applied`` after the action term writes it, [N, 6]."""
    term = env.action_manager.get_term("joint_pos")
    term.apply_actions()
    robot = env.scene["robot"]
    body = robot.indexing.body_ids[robot.find_bodies(("pelvis",))[0][0]]
    return env.sim.data.xfrc_applied[:, body].clone()


def test_assist_wrench_in_the_env(env: Any) -> None:
    """Scale 0: no wrench on the pelvis; scale 0.5 with the base 5 cm low: the PD law, halved; back to 0: none."""
    _place_on_reference(env, 0.2)
    robot = env.scene["robot"]
    root = torch.cat([robot.data.root_link_pos_w, robot.data.root_link_quat_w], dim=-1).clone()
    root[:, 2] -= 0.05
    robot.write_root_link_pose_to_sim(root)
    env.sim.forward()
    state = get_assist(env)
    state.scale = 0.0
    assert torch.count_nonzero(_pelvis_wrench(env)) == 0
    state.scale = 0.5
    wrench = _pelvis_wrench(env)
    jump, data = get_jump(env), robot.data
    force, torque = assist_wrench(
        jump.cfg.task.assist,
        0.5,
        data.root_link_pos_w,
        data.root_link_quat_w,
        data.root_link_lin_vel_w,
        data.root_link_ang_vel_w,
        jump.reference("base_pos"),
        jump.reference("base_quat"),
        jump.reference("base_lin_vel"),
        jump.reference("base_ang_vel"),
    )
    torch.testing.assert_close(wrench, torch.cat([force, torque], dim=-1))
    # 0.5 * kp_pos * 0.05 m = 0.5 * 2000 * 0.05 = 50 N upward
    assert wrench[:, 2].cpu().tolist() == pytest.approx([50.0] * env.num_envs, abs=1e-2)
    state.scale = 0.0  # annealed away: the wrench written at 0.5 is cleared
    assert torch.count_nonzero(_pelvis_wrench(env)) == 0


def test_reference_state_initialization(env: Any) -> None:
    """With RSI every reset starts inside the motion, in the reference state of its start time."""
    jump = get_jump(env)
    jump.cfg.task = replace(jump.cfg.task, rsi_probability=1.0)
    try:
        env.reset()
        start = jump.start_time.cpu()
        assert ((start >= 0.0) & (start <= jump.ref.duration)).all() and start.unique().numel() == env.num_envs
        robot = env.scene["robot"]
        torch.testing.assert_close(robot.data.root_link_pos_w, jump.reference("base_pos"), atol=1e-5, rtol=0.0)
        torch.testing.assert_close(robot.data.joint_pos, jump.reference("joint_pos"), atol=1e-5, rtol=0.0)
    finally:
        jump.cfg.task = replace(jump.cfg.task, rsi_probability=0.0)
