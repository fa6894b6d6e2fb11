# SPDX-License-Identifier: Apache-2.0
"""Actor (policy), critic (privileged) and optional history observation groups of the granular G1 task."""

from __future__ import annotations

from mjlab.managers.observation_manager import ObservationGroupCfg, ObservationTermCfg
from mjlab.tasks.velocity import mdp as vel_mdp
from mjlab.utils.noise import UniformNoiseCfg

from gmloco.train import mdp
from gmloco.train.config import GranularTaskCfg

__all__ = ["ACTOR_TERMS", "ACTOR_TERM_DESCRIPTIONS", "CRITIC_EXTRA_TERMS", "HISTORY_GROUP", "make_observations_cfg"]

ACTOR_TERMS = ("base_ang_vel", "projected_gravity", "command", "joint_pos", "joint_vel", "actions")
"""Actor observation terms, in order (29-DoF G1: 3 + 3 + 3 + 29 + 29 + 29 = 96 per frame)."""
ACTOR_TERM_DESCRIPTIONS = {
    "base_ang_vel": "IMU angular velocity (x, y, z) in the pelvis IMU frame [rad/s]",
    "projected_gravity": "unit gravity direction in the pelvis frame (0, 0, -1 upright) [-]",
    "command": "velocity command (v_x [m/s], v_y [m/s], omega_z [rad/s]) in the base yaw frame",
    "joint_pos": "q - q_0 per joint, joints order [rad]",
    "joint_vel": "joint velocity per joint, joints order [rad/s]",
    "actions": "the policy's previous raw action (before action_scale), joints order [-]",
}
"""What each actor term is (frame, order, SI unit), written into the exported policy's metadata."""
CRITIC_EXTRA_TERMS = (
    "base_lin_vel",
    "foot_height",
    "foot_contact",
    "foot_contact_forces",
    "foot_air_time",
    "eta",
)
"""Privileged terms appended to the (noise-free) actor terms in the critic group."""
HISTORY_GROUP = "history"
"""Group of the last N actor frames, ``[num_envs, N, 96]`` (oldest first; the teacher encoder and student read it)."""


def _noise(half_width: float, scale: float) -> UniformNoiseCfg | None:
    """Uniform noise U[-w, w] scaled by ``scale`` (None when it vanishes)."""
    w = half_width * scale
    return UniformNoiseCfg(n_min=-w, n_max=w) if w > 0.0 else None


def _actor_terms(noise_scale: float) -> dict[str, ObservationTermCfg]:
    """Proprioceptive terms; noise ranges from Isaac Lab / mjlab velocity tasks."""
    return {
        "base_ang_vel": ObservationTermCfg(
            func=vel_mdp.builtin_sensor,
            params={"sensor_name": "robot/imu_ang_vel"},
            noise=_noise(0.2, noise_scale),
        ),
        "projected_gravity": ObservationTermCfg(func=vel_mdp.projected_gravity, noise=_noise(0.05, noise_scale)),
        "command": ObservationTermCfg(func=vel_mdp.generated_commands, params={"command_name": "twist"}),
        "joint_pos": ObservationTermCfg(func=vel_mdp.joint_pos_rel, noise=_noise(0.01, noise_scale)),
        "joint_vel": ObservationTermCfg(func=vel_mdp.joint_vel_rel, noise=_noise(1.5, noise_scale)),
        "actions": ObservationTermCfg(func=vel_mdp.last_action),
    }


def _critic_terms() -> dict[str, ObservationTermCfg]:
    """Noise-free actor terms plus privileged contact and terrain terms."""
    return {
        **_actor_terms(0.0),
        "base_lin_vel": ObservationTermCfg(func=vel_mdp.builtin_sensor, params={"sensor_name": "robot/imu_lin_vel"}),
        "foot_height": ObservationTermCfg(func=mdp.foot_height),
        "foot_contact": ObservationTermCfg(func=mdp.foot_contact),
        "foot_contact_forces": ObservationTermCfg(func=mdp.foot_contact_forces),
        "foot_air_time": ObservationTermCfg(func=mdp.foot_air_time),
        "eta": ObservationTermCfg(func=mdp.terrain_eta),
    }


def make_observations_cfg(task: GranularTaskCfg, history_length: int = 0) -> dict[str, ObservationGroupCfg]:
    """Return the ``actor`` and ``critic`` groups (rsl-rl / mjlab group names), plus ``history`` if asked.

    Args:
        task: The task config (noise, play mode, stacked actor frames).
        history_length: N > 0 adds the ``history`` group: the six actor terms over the last N policy steps,
            ``[num_envs, N, 96]`` (mjlab ``flatten_history_dim=False``), with the actor's noise. 0 leaves it out,
            so vanilla PPO does not store N frames per env and step in its rollout buffer.
    """
    history = task.policy_history_length if task.policy_history_length > 1 else None
    noise = 0.0 if task.play else task.obs_noise_scale
    groups = {
        "actor": ObservationGroupCfg(terms=_actor_terms(noise), enable_corruption=noise > 0.0, history_length=history),
        "critic": ObservationGroupCfg(terms=_critic_terms(), enable_corruption=False),
    }
    if history_length > 0:
        groups[HISTORY_GROUP] = ObservationGroupCfg(
            terms=_actor_terms(noise),
            enable_corruption=noise > 0.0,
            history_length=history_length,
            flatten_history_dim=False,
        )
    return groups
