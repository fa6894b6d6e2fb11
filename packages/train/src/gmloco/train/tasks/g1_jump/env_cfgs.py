# SPDX-License-Identifier: Apache-2.0
"""Factory of the G1 jump imitation env on mjlab 1.6 (same scene, sand contact and PD actuators as the walk task)."""

from __future__ import annotations

import math

from mjlab.envs import ManagerBasedRlEnvCfg
from mjlab.envs import mdp as envs_mdp
from mjlab.managers.curriculum_manager import CurriculumTermCfg
from mjlab.managers.event_manager import EventTermCfg
from mjlab.managers.observation_manager import ObservationGroupCfg, ObservationTermCfg
from mjlab.managers.reward_manager import RewardTermCfg
from mjlab.managers.termination_manager import TerminationTermCfg
from mjlab.sim import MujocoCfg, SimulationCfg
from mjlab.tasks.velocity import mdp as vel_mdp
from mjlab.viewer import ViewerConfig

from gmloco.train import mdp as granular_mdp
from gmloco.train.tasks.g1_granular.env_cfgs import NJMAX, _scene
from gmloco.train.tasks.g1_granular.events_cfg import make_events_cfg
from gmloco.train.tasks.g1_granular.observations_cfg import _noise
from gmloco.train.tasks.g1_jump import mdp
from gmloco.train.tasks.g1_jump.assist import AssistedJointPositionActionCfg, assist_scale_curriculum
from gmloco.train.tasks.g1_jump.command import JUMP_COMMAND, JumpReferenceCommandCfg
from gmloco.train.tasks.g1_jump.config import JumpTaskCfg
from gmloco.train.tasks.g1_jump.reference import load_reference, reference_path

__all__ = ["JUMP_ACTOR_TERMS", "episode_length_s", "make_g1_jump_env_cfg"]

JUMP_ACTOR_TERMS = ("base_ang_vel", "projected_gravity", "phase", "joint_pos", "joint_vel", "actions")
"""Actor observation terms, in order (3 + 3 + 2 + 29 + 29 + 29 = 95 per frame)."""


def episode_length_s(task: JumpTaskCfg) -> float:
    """Reference duration plus the hold [s]."""
    return load_reference(reference_path(task.motion)).duration + task.hold_s


def _actor_terms(noise_scale: float) -> dict[str, ObservationTermCfg]:
    """Proprioception and the phase; the noise ranges are the walk task's."""
    return {
        "base_ang_vel": ObservationTermCfg(
            func=vel_mdp.builtin_sensor, params={"sensor_name": "robot/imu_ang_vel"}, noise=_noise(0.2, noise_scale)
        ),
        "projected_gravity": ObservationTermCfg(func=vel_mdp.projected_gravity, noise=_noise(0.05, noise_scale)),
        "phase": ObservationTermCfg(func=mdp.jump_phase),
        "joint_pos": ObservationTermCfg(func=vel_mdp.joint_pos_rel, noise=_noise(0.01, noise_scale)),
        "joint_vel": ObservationTermCfg(func=vel_mdp.joint_vel_rel, noise=_noise(1.5, noise_scale)),
        "actions": ObservationTermCfg(func=vel_mdp.last_action),
    }


def _observations(task: JumpTaskCfg) -> dict[str, ObservationGroupCfg]:
    """Actor: proprioception + phase (stacked frames); critic: noise-free actor terms + privileged state."""
    b = task.base
    noise = 0.0 if b.play else b.obs_noise_scale
    history = b.policy_history_length if b.policy_history_length > 1 else None
    critic = {
        **_actor_terms(0.0),
        "base_lin_vel": ObservationTermCfg(func=vel_mdp.builtin_sensor, params={"sensor_name": "robot/imu_lin_vel"}),
        "reference_base_error": ObservationTermCfg(func=mdp.reference_base_error),
        "foot_height": ObservationTermCfg(func=granular_mdp.foot_height),
        "foot_contact": ObservationTermCfg(func=granular_mdp.foot_contact),
        "eta": ObservationTermCfg(func=granular_mdp.terrain_eta),
        "assist_scale": ObservationTermCfg(func=mdp.assist_scale),
    }
    return {
        "actor": ObservationGroupCfg(terms=_actor_terms(noise), enable_corruption=noise > 0.0, history_length=history),
        "critic": ObservationGroupCfg(terms=critic, enable_corruption=False),
    }


def _rewards(task: JumpTaskCfg) -> dict[str, RewardTermCfg]:
    """Tracking kernels and regularizers; a weight of 0 drops the term."""
    r = task.rewards
    kernels = {
        "track_joint_pos": (mdp.track_joint_pos_exp, r.joint_pos_weight, r.joint_pos_std),
        "track_joint_vel": (mdp.track_joint_vel_exp, r.joint_vel_weight, r.joint_vel_std),
        "track_base_pos": (mdp.track_base_pos_exp, r.base_pos_weight, r.base_pos_std),
        "track_base_ori": (mdp.track_base_ori_exp, r.base_ori_weight, r.base_ori_std),
        "track_base_lin_vel": (mdp.track_base_lin_vel_exp, r.base_lin_vel_weight, r.base_lin_vel_std),
        "track_base_ang_vel": (mdp.track_base_ang_vel_exp, r.base_ang_vel_weight, r.base_ang_vel_std),
        "track_feet_pos": (mdp.track_feet_pos_exp, r.feet_pos_weight, r.feet_pos_std),
    }
    terms = {name: RewardTermCfg(func=f, weight=w, params={"std": std}) for name, (f, w, std) in kernels.items()}
    terms |= {
        "feet_contact_match": RewardTermCfg(func=mdp.feet_contact_match, weight=r.contact_match_weight),
        "action_rate_l2": RewardTermCfg(func=envs_mdp.action_rate_l2, weight=r.action_rate_weight),
        "joint_pos_limits": RewardTermCfg(func=envs_mdp.joint_pos_limits, weight=r.joint_limits_weight),
        "termination_penalty": RewardTermCfg(func=envs_mdp.is_terminated, weight=r.termination_weight),
    }
    return {name: term for name, term in terms.items() if term.weight != 0.0}


def _terminations(task: JumpTaskCfg) -> dict[str, TerminationTermCfg]:
    """The walk task's failure rules (70 deg tilt, pelvis 0.3 m above the sand) plus losing the reference or diverged physics."""
    return {
        "time_out": TerminationTermCfg(func=vel_mdp.time_out, time_out=True),
        "fell_over": TerminationTermCfg(func=vel_mdp.bad_orientation, params={"limit_angle": math.radians(70.0)}),
        "base_too_low": TerminationTermCfg(func=granular_mdp.base_height_below, params={"min_height": 0.3}),
        "tracking_lost": TerminationTermCfg(func=mdp.tracking_lost, params={"max_error": task.max_base_pos_error}),
        "physics_diverged": TerminationTermCfg(func=granular_mdp.physics_diverged),
    }


def _events(task: JumpTaskCfg) -> dict[str, EventTermCfg]:
    """Sand contact on reset and the startup robot DR of the walk task; RSI replaces the random reset pose."""
    events = make_events_cfg(task.base)
    for name in ("reset_base", "reset_robot_joints", "push_robot"):
        events.pop(name, None)
    return events


def make_g1_jump_env_cfg(task: JumpTaskCfg, num_envs: int = 4096) -> ManagerBasedRlEnvCfg:
    """Build the mjlab env config of the jump task: 50 Hz policy (decimation 4) over 200 Hz physics."""
    curriculum = {}
    if task.assist.enabled and not task.base.play:
        curriculum["assist_scale"] = CurriculumTermCfg(func=assist_scale_curriculum)
    return ManagerBasedRlEnvCfg(
        scene=_scene(task.base, num_envs),
        observations=_observations(task),
        actions={
            "joint_pos": AssistedJointPositionActionCfg(
                entity_name="robot",
                actuator_names=(".*",),
                scale=task.base.action_scale,
                use_default_offset=True,
                assist=task.assist,
            )
        },
        commands={JUMP_COMMAND: JumpReferenceCommandCfg(task=task)},
        events=_events(task),
        rewards=_rewards(task),
        terminations=_terminations(task),
        curriculum=curriculum,
        viewer=ViewerConfig(
            origin_type=ViewerConfig.OriginType.ASSET_BODY, entity_name="robot", body_name="torso_link", distance=3.0
        ),
        sim=SimulationCfg(
            njmax=NJMAX,
            contact_sensor_maxmatch=64,
            mujoco=MujocoCfg(timestep=0.005, iterations=10, ls_iterations=20, ccd_iterations=50),
        ),
        decimation=4,
        episode_length_s=episode_length_s(task),
    )
