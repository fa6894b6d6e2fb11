# SPDX-License-Identifier: Apache-2.0
"""Typed configuration of the G1 jump imitation task (pure data; built by ``tasks.g1_jump.env_cfgs``)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal

from gmloco.train.config import ContactModelName, GranularTaskCfg, SandFloorCfg, SandTerrainCfg

__all__ = [
    "JumpAssistCfg",
    "JumpImitationCfg",
    "JumpMotionName",
    "JumpRewardCfg",
    "JumpTaskCfg",
    "g1_jump_task",
    "jump_terrain",
]

JumpMotionName = Literal["vertical", "forward"]
"""Shipped jump references (``tasks/g1_jump/data/jump_<name>.npz``)."""


@dataclass
class JumpAssistCfg:
    """Assistive wrench on the pelvis toward the reference base pose, annealed by tracking success.

    ZEST (Sleiman et al. 2026) helps an imitation policy through dynamic skills with a virtual wrench on the base
    that a curriculum removes; the final policy runs without it. Here the wrench is a PD law on the base position
    and orientation error, times a scale in [0, 1] shared by all envs.
    """

    enabled: bool = True
    """Apply the wrench at all (False: scale fixed at 0, no curriculum)."""
    kp_pos: float = 2000.0
    """Position gain [N/m] (about 6 m g per metre of error for the 33 kg G1)."""
    kd_pos: float = 200.0
    """Linear velocity gain [N s/m]."""
    kp_rot: float = 400.0
    """Orientation gain [N m/rad]."""
    kd_rot: float = 40.0
    """Angular velocity gain [N m s/rad]."""
    max_force: float = 650.0
    """Cap on |force| [N] (twice the G1's weight)."""
    max_torque: float = 150.0
    """Cap on |torque| [N m]."""
    initial_scale: float = field(default=1.0, metadata={"ge": 0, "le": 1})
    """Scale at the start of training [-]."""
    scale_step: float = field(default=0.02, metadata={"gt": 0, "le": 1})
    """Scale removed each time the success rate clears ``success_threshold`` [-]."""
    success_threshold: float = field(default=0.8, metadata={"gt": 0, "le": 1})
    """Moving-average fraction of episodes ending without a failure above which the scale drops [-]."""
    success_ema: float = 0.05
    """Weight of each reset batch in the moving average of the success rate [-]."""
    min_episodes_per_env: float = 2.0
    """Finished episodes per env needed between two scale changes [-]: at 4,096 envs a new scale is judged on
    ~8k episodes, and the scale reaches 0 after at least 50 such rounds (~730 iterations of 24 steps)."""


@dataclass
class JumpRewardCfg:
    """Tracking kernels exp(-err^2 / std^2) and their weights (DeepMimic-style imitation terms)."""

    joint_pos_std: float = 0.25
    """Std of the RMS joint position error [rad]."""
    joint_pos_weight: float = 1.0
    """Weight of joint position tracking."""
    joint_vel_std: float = 2.0
    """Std of the RMS joint velocity error [rad/s]."""
    joint_vel_weight: float = 0.25
    """Weight of joint velocity tracking."""
    base_pos_std: float = 0.1
    """Std of the base position error [m]."""
    base_pos_weight: float = 1.5
    """Weight of base position tracking (carries the jump height and distance)."""
    base_ori_std: float = 0.3
    """Std of the base orientation error angle [rad]."""
    base_ori_weight: float = 0.5
    """Weight of base orientation tracking."""
    base_lin_vel_std: float = 0.5
    """Std of the base linear velocity error [m/s]."""
    base_lin_vel_weight: float = 0.5
    """Weight of base linear velocity tracking."""
    base_ang_vel_std: float = 1.5
    """Std of the base angular velocity error [rad/s]."""
    base_ang_vel_weight: float = 0.25
    """Weight of base angular velocity tracking."""
    feet_pos_std: float = 0.06
    """Std of the RMS sole-site position error [m]."""
    feet_pos_weight: float = 1.0
    """Weight of feet position tracking."""
    contact_match_weight: float = 0.5
    """Weight of the fraction of feet whose contact state matches the reference's."""
    action_rate_weight: float = -0.01
    """Weight of the squared action change."""
    joint_limits_weight: float = -2.0
    """Weight of the joint soft-limit violation."""
    termination_weight: float = -50.0
    """Weight of a failure (not of a time out)."""


@dataclass
class JumpImitationCfg:
    """The imitation side of a jump task: reference, episode, rewards and assist (the pipeline's ``jump`` section)."""

    motion: JumpMotionName = "vertical"
    """Reference motion."""
    hold_s: float = field(default=1.0, metadata={"ge": 0})
    """Time the episode runs on after the reference ends, holding its last (standing) frame [s]."""
    rsi_probability: float = field(default=0.8, metadata={"ge": 0, "le": 1})
    """Probability that a reset starts at a random time of the reference (reference state initialization,
    Peng et al. 2018) instead of its first frame."""
    max_base_pos_error: float = field(default=0.35, metadata={"gt": 0})
    """Base position error that ends the episode as a failure [m]."""
    rewards: JumpRewardCfg = field(default_factory=JumpRewardCfg)
    """Tracking rewards."""
    assist: JumpAssistCfg = field(default_factory=JumpAssistCfg)
    """Assistive wrench and its curriculum."""


@dataclass
class JumpTaskCfg(JumpImitationCfg):
    """Everything that selects one G1 jump task; ``make_g1_jump_env_cfg`` builds it."""

    base: GranularTaskCfg = field(default_factory=GranularTaskCfg)
    """Contact model, sand material DR, robot DR, action scale, noise, play mode (velocity-task fields that the
    jump does not use are ignored: commands, velocity rewards, floor curriculum)."""


def jump_terrain(contact_model: ContactModelName) -> SandTerrainCfg:
    """Flat sand over a hard floor 12 cm down (GM-Loco's deepest level); rigid contact stands on the floor itself."""
    depth = 0.0 if contact_model == "rigid" else 0.12
    floor = SandFloorCfg(depth_range=(depth, depth), num_levels=1, curriculum=False)
    return SandTerrainCfg(kind="flat", floor=floor)


def g1_jump_task(
    contact_model: ContactModelName = "rft3d", motion: JumpMotionName = "vertical", play: bool = False
) -> JumpTaskCfg:
    """Return the jump task for one contact model (PPO-3D-RFT: ``"rft3d"``, PPO-Rigid: ``"rigid"``) and motion."""
    base = replace(
        GranularTaskCfg(contact_model=contact_model, play=play),
        terrain=jump_terrain(contact_model),
        command_curriculum=False,
        reward_ramp_steps=0,
    )
    task = JumpTaskCfg(base=base, motion=motion)
    if play:
        task = replace(task, rsi_probability=0.0, assist=replace(task.assist, enabled=False))
    return task
