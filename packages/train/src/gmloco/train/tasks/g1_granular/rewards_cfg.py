# SPDX-License-Identifier: Apache-2.0
"""GM-Loco reward set (2026 code weights, spec section 4) and its curricula, as mjlab term configs."""

from __future__ import annotations

import math
from typing import Any

from mjlab.envs import mdp as envs_mdp
from mjlab.managers.curriculum_manager import CurriculumTermCfg
from mjlab.managers.reward_manager import RewardTermCfg
from mjlab.managers.scene_entity_config import SceneEntityCfg
from mjlab.tasks.velocity.config.g1.env_cfgs import unitree_g1_rough_env_cfg

from gmloco.train import mdp
from gmloco.train.config import GranularTaskCfg

__all__ = ["LOWER_BODY_JOINTS", "UPPER_BODY_JOINTS", "command_stages", "make_curriculum_cfg", "make_rewards_cfg"]

CMD = "twist"
"""Name of the velocity command term."""
LOWER_BODY_JOINTS = (r".*_hip_.*", r".*_knee_.*", r".*_ankle_.*")
"""Leg joints (action-rate weight -0.01)."""
UPPER_BODY_JOINTS = (r"waist_.*", r".*_shoulder_.*", r".*_elbow_.*", r".*_wrist_.*")
"""Waist and arm joints (action-rate weight -0.05)."""


def _posture_stds() -> dict[str, dict[str, float]]:
    """Mjlab's G1 per-joint pose tolerances (standing / walking / running) [rad]."""
    params = unitree_g1_rough_env_cfg().rewards["pose"].params
    return {k: params[k] for k in ("std_standing", "std_walking", "std_running")}


def _tracking_terms(task: GranularTaskCfg) -> dict[str, RewardTermCfg]:
    """Velocity and heading tracking (exp kernels); the heading term follows ``task.yaw_command``."""
    std = math.sqrt(0.5)
    heading = (
        {
            "track_yaw_target_exp": RewardTermCfg(
                func=mdp.track_yaw_target_exp, weight=4.0, params={"std": std, "command_name": CMD}
            )
        }
        if task.yaw_command == "yaw_target"
        else {
            "track_heading_exp": RewardTermCfg(
                func=mdp.track_heading_exp, weight=4.0, params={"std": std, "command_name": CMD}
            )
        }
    )
    return {
        "track_lin_vel_xy_exp": RewardTermCfg(
            func=mdp.track_lin_vel_xy_exp, weight=4.0, params={"std": std, "command_name": CMD}
        ),
        **heading,
        "track_ang_vel_z_exp": RewardTermCfg(
            func=mdp.track_ang_vel_z_exp, weight=1.0, params={"std": std, "command_name": CMD}
        ),
    }


def _base_terms() -> dict[str, RewardTermCfg]:
    """Termination, base height / orientation / velocity penalties."""
    return {
        "termination_penalty": RewardTermCfg(func=envs_mdp.is_terminated, weight=-200.0),
        "base_height_l2": RewardTermCfg(func=mdp.base_height_l2, weight=-10.0, params={"target_height": 0.75}),
        "flat_orientation_l2": RewardTermCfg(func=mdp.flat_orientation_l2, weight=-10.0),
        "lin_vel_z_l2": RewardTermCfg(func=mdp.lin_vel_z_l2, weight=-1.0),
        "ang_vel_xy_l2": RewardTermCfg(func=mdp.ang_vel_xy_l2, weight=-0.05),
        "undesired_contacts": RewardTermCfg(
            func=mdp.undesired_contacts, weight=-1.0, params={"sensor_name": "undesired_floor_contact"}
        ),
    }


def _joint_terms() -> dict[str, RewardTermCfg]:
    """Action rate, energy, joint velocity / acceleration / limits, posture."""
    return {
        "action_rate_lower_l2": RewardTermCfg(
            func=mdp.action_rate_l2, weight=-0.01, params={"joint_names": LOWER_BODY_JOINTS}
        ),
        "action_rate_upper_l2": RewardTermCfg(
            func=mdp.action_rate_l2, weight=-0.05, params={"joint_names": UPPER_BODY_JOINTS}
        ),
        "energy": RewardTermCfg(func=mdp.energy, weight=-1e-3),
        "joint_vel_l2": RewardTermCfg(func=mdp.joint_vel_l2, weight=-2e-4),
        "joint_acc_l2": RewardTermCfg(func=mdp.joint_acc_l2, weight=-2.5e-7),
        "joint_pos_limits": RewardTermCfg(func=envs_mdp.joint_pos_limits, weight=-2.0),
        "variable_posture_l1": RewardTermCfg(
            func=mdp.variable_posture_l1,
            weight=-1.0,
            params={
                "asset_cfg": SceneEntityCfg("robot", joint_names=(".*",)),
                "command_name": CMD,
                "walking_threshold": 0.05,
                "running_threshold": 1.5,
                **_posture_stds(),
            },
        ),
    }


def _clearance_term(task: GranularTaskCfg) -> dict[str, RewardTermCfg]:
    """Swing-height terms: L2 penalty (default), the code's exp reward, or the penalty plus the touchdown lift."""
    if task.foot_clearance == "reward":
        return {
            "foot_clearance": RewardTermCfg(
                func=mdp.foot_clearance, weight=5.0, params={"target_height": 0.10, "std": 0.05, "tanh_mult": 2.0}
            )
        }
    if task.foot_clearance == "sinkage":
        return _sinkage_clearance_terms()
    terms = {
        "foot_clearance_l2": RewardTermCfg(
            func=mdp.foot_clearance_l2, weight=-2.0, params={"target_height": 0.10, "tanh_mult": 2.0}
        )
    }
    if task.foot_clearance == "touchdown":
        # Measured on the clr50 teacher (CPU, 8 envs, dry sand, 1 m/s): 4.4 touchdowns/s, mean lift 6.0 cm, so
        # weight 100 pays 100 x 0.06 x 4.4 x 0.02 s = 0.53 per second now (tracking: 3.8; the L2 penalty at -50:
        # -0.51) and as much again for lifting to the 12 cm cap.
        terms["swing_height_at_touchdown"] = RewardTermCfg(
            func=mdp.swing_height_at_touchdown,
            weight=100.0,
            params={"target_height": 0.12, "command_name": CMD, "relative": True},
        )
    return terms


SINKAGE_CLEARANCE = {"target_height": 0.09, "sinkage_gain": 1.0, "max_height": 0.20}
"""Swing target of ``foot_clearance="sinkage"``: 9 cm above the surface on stiff ground (the project page's
basalt-like apex) plus the footprint depth (gain 1: 7 cm sinkage in poppy seed, measured in
artifacts/gm_loco_student_td/README.md as lift minus apex, gives ~16 cm), at most 20 cm [m, -, m]."""


def _sinkage_clearance_terms() -> dict[str, RewardTermCfg]:
    """The touchdown mode's two terms (names, weights) with the sinkage-aware target of :data:`SINKAGE_CLEARANCE`."""
    return {
        "foot_clearance_l2": RewardTermCfg(
            func=mdp.foot_clearance_sinkage_l2, weight=-2.0, params={**SINKAGE_CLEARANCE, "tanh_mult": 2.0}
        ),
        "swing_height_at_touchdown": RewardTermCfg(
            func=mdp.swing_apex_sinkage_at_touchdown,
            weight=100.0,
            params={**SINKAGE_CLEARANCE, "command_name": CMD},
        ),
    }


def _feet_terms(task: GranularTaskCfg) -> dict[str, RewardTermCfg]:
    """Foot orientation, gait and contact terms (signals from the granular model)."""
    return {
        "feet_roll_l2": RewardTermCfg(func=mdp.feet_roll_l2, weight=-1.0),
        "feet_roll_diff_l2": RewardTermCfg(func=mdp.feet_roll_diff_l2, weight=-1.0),
        "feet_pitch_l2": RewardTermCfg(func=mdp.feet_pitch_l2, weight=-4.0),
        "feet_pitch_diff_l2": RewardTermCfg(func=mdp.feet_pitch_diff_l2, weight=-4.0),
        "feet_pitch_in_contact_l2": RewardTermCfg(func=mdp.feet_pitch_in_contact_l2, weight=-4.0),
        "feet_air_time": RewardTermCfg(
            func=mdp.feet_air_time, weight=0.5, params={"threshold": 0.5, "command_name": CMD}
        ),
        "no_fly": RewardTermCfg(func=mdp.no_fly, weight=-1.0, params={"command_name": CMD}),
        "feet_lateral_distance": RewardTermCfg(func=mdp.feet_lateral_distance, weight=-2.0, params={"min_gap": 0.2}),
        "feet_slide": RewardTermCfg(func=mdp.feet_slide, weight=-0.25),
        "contact_impulse": RewardTermCfg(func=mdp.contact_impulse, weight=-0.005, params={"command_name": CMD}),
        **_clearance_term(task),
    }


def make_rewards_cfg(task: GranularTaskCfg) -> dict[str, RewardTermCfg]:
    """Return the reward terms with ``task.reward_weights`` overrides applied (weight 0 drops a term)."""
    rewards = {**_tracking_terms(task), **_base_terms(), **_joint_terms(), **_feet_terms(task)}
    unknown = set(task.reward_weights) - set(rewards)
    if unknown:
        raise KeyError(f"Unknown reward terms in reward_weights: {sorted(unknown)}")
    for name, weight in task.reward_weights.items():
        rewards[name].weight = weight
    return {name: term for name, term in rewards.items() if term.weight != 0.0}


def command_stages(task: GranularTaskCfg) -> list[dict[str, Any]]:
    """GM-Loco's command-range stages: from env step ``step`` on, ``lin_vel_x`` [m/s] and ``ang_vel_z`` [rad/s]."""
    step2, step3 = (round(s * task.curriculum_scale) for s in task.command_stage_steps)
    return [
        {"step": 0, "lin_vel_x": (-1.0, 1.0), "ang_vel_z": (-0.5, 0.5)},
        {"step": step2, "lin_vel_x": (-1.0, 1.7), "ang_vel_z": (-0.7, 0.7)},
        {"step": step3, "lin_vel_x": (-1.0, 2.5), "ang_vel_z": (-1.0, 1.0)},
    ]


def make_curriculum_cfg(task: GranularTaskCfg, rewards: dict[str, RewardTermCfg]) -> dict[str, CurriculumTermCfg]:
    """Floor-depth levels, command-range stages and tracking ramps (GM-Loco schedule)."""
    if task.play:
        return {}
    cur: dict[str, CurriculumTermCfg] = {}
    if task.contact_model != "rigid" and task.terrain.floor.curriculum:
        cur["sand_floor_levels"] = CurriculumTermCfg(func=mdp.sand_floor_levels, params={"command_name": CMD})
    if task.command_curriculum:
        from mjlab.tasks.velocity import mdp as vel_mdp

        cur["command_vel"] = CurriculumTermCfg(
            func=vel_mdp.commands_vel, params={"command_name": CMD, "velocity_stages": command_stages(task)}
        )
    ramp_steps = round(task.reward_ramp_steps * task.curriculum_scale)
    if ramp_steps > 0:
        std = ("std", math.sqrt(1.0), math.sqrt(0.1))
        for name in ("track_lin_vel_xy_exp", "track_heading_exp", "track_yaw_target_exp", "track_ang_vel_z_exp"):
            if name not in rewards:
                continue
            w = rewards[name].weight
            weight = (w, 2.0 * w) if name != "track_ang_vel_z_exp" else None
            cur[f"ramp_{name}"] = CurriculumTermCfg(
                func=mdp.reward_ramp,
                params={
                    "reward_name": name,
                    "num_steps": ramp_steps,
                    "weight": weight,
                    "param": std,
                },
            )
    return cur
