# SPDX-License-Identifier: Apache-2.0
"""Event terms: sand contact (materials, floor), resets and robot domain randomization."""

from __future__ import annotations

from mjlab.envs.mdp import dr
from mjlab.managers.event_manager import EventTermCfg
from mjlab.managers.scene_entity_config import SceneEntityCfg
from mjlab.tasks.velocity import mdp as vel_mdp

from gmloco.train.config import GranularTaskCfg
from gmloco.train.sand import SandContact

__all__ = ["FOOT_GEOMS", "make_events_cfg"]

FOOT_GEOMS = tuple(f"{side}_foot{i}_collision" for side in ("left", "right") for i in range(1, 8))
"""The seven sole capsules of each G1 foot."""


def _reset_terms(task: GranularTaskCfg) -> dict[str, EventTermCfg]:
    """Sand contact first, then root pose and joints."""
    offset = task.robot_dr.joint_pos_offset if task.robot_dr.enabled and not task.play else 0.0
    return {
        "sand_contact": EventTermCfg(func=SandContact, mode="reset", params={"task": task}),
        "reset_base": EventTermCfg(
            func=vel_mdp.reset_root_state_uniform,
            mode="reset",
            params={
                "pose_range": {"x": (-0.5, 0.5), "y": (-0.5, 0.5), "yaw": (-3.14, 3.14)},
                "velocity_range": {},
            },
        ),
        "reset_robot_joints": EventTermCfg(
            func=vel_mdp.reset_joints_by_offset,
            mode="reset",
            params={
                "position_range": (-offset, offset),
                "velocity_range": (0.0, 0.0),
                "asset_cfg": SceneEntityCfg("robot", joint_names=(".*",)),
            },
        ),
    }


def _robot_dr_terms(task: GranularTaskCfg) -> dict[str, EventTermCfg]:
    """Added torso mass, CoM offset, PD-gain scale, foot friction (startup) and pushes (interval)."""
    r = task.robot_dr
    com = (-r.com_offset, r.com_offset)
    torso = SceneEntityCfg("robot", body_names=("torso_link",))
    v = r.push_velocity
    return {
        "added_mass": EventTermCfg(
            func=dr.body_mass,
            mode="startup",
            params={"asset_cfg": torso, "operation": "add", "ranges": r.added_mass},
        ),
        "base_com": EventTermCfg(
            func=dr.body_com_offset,
            mode="startup",
            params={
                "asset_cfg": SceneEntityCfg("robot", body_names=("torso_link",)),
                "ranges": {0: com, 1: com, 2: com},
            },
        ),
        "actuator_gains": EventTermCfg(
            func=dr.pd_gains,
            mode="startup",
            params={"kp_range": r.actuator_gain, "kd_range": r.actuator_gain, "operation": "scale"},
        ),
        "foot_friction": EventTermCfg(
            func=dr.geom_friction,
            mode="startup",
            params={
                "asset_cfg": SceneEntityCfg("robot", geom_names=FOOT_GEOMS),
                "operation": "abs",
                "ranges": r.foot_friction,
                "shared_random": True,
            },
        ),
        "push_robot": EventTermCfg(
            func=vel_mdp.push_by_setting_velocity,
            mode="interval",
            interval_range_s=r.push_interval_s,
            params={"velocity_range": {"x": (-v, v), "y": (-v, v)}},
        ),
    }


def make_events_cfg(task: GranularTaskCfg) -> dict[str, EventTermCfg]:
    """Return the event terms; robot DR is dropped in play mode or when disabled."""
    events = _reset_terms(task)
    if task.robot_dr.enabled and not task.play:
        events.update(_robot_dr_terms(task))
    return events
