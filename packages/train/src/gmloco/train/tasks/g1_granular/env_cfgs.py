# SPDX-License-Identifier: Apache-2.0
"""Factory functions for the Unitree G1 29-DoF velocity task on sand (mjlab 1.6)."""

from __future__ import annotations

import math
from dataclasses import replace
from functools import partial

from mjlab.asset_zoo.robots import get_g1_robot_cfg
from mjlab.envs import ManagerBasedRlEnvCfg
from mjlab.envs.mdp.actions import JointPositionActionCfg
from mjlab.managers.termination_manager import TerminationTermCfg
from mjlab.scene import SceneCfg
from mjlab.sensor import ContactMatch, ContactSensorCfg
from mjlab.sim import MujocoCfg, SimulationCfg
from mjlab.tasks.velocity import mdp as vel_mdp
from mjlab.tasks.velocity.mdp import UniformVelocityCommandCfg
from mjlab.viewer import ViewerConfig

from gmloco.train import mdp
from gmloco.train.config import (
    ContactModelName,
    GranularTaskCfg,
    MaterialRangeCfg,
    TerrainName,
    deep_sand_terrain,
    flat_sand_terrain,
    rough_sand_terrain,
)
from gmloco.train.mdp.commands import YawTargetVelocityCommandCfg
from gmloco.train.sand import FEET_FLOOR_SENSOR, FOOT_BODIES, SAND_FLOOR_BODY, add_sand_floor
from gmloco.train.tasks.g1_granular.events_cfg import make_events_cfg
from gmloco.train.tasks.g1_granular.observations_cfg import make_observations_cfg
from gmloco.train.tasks.g1_granular.rewards_cfg import make_curriculum_cfg, make_rewards_cfg

__all__ = ["g1_granular_task", "make_g1_granular_env_cfg"]

_UNDESIRED_BODIES = r"^(pelvis|torso_link|.*_hip_.*_link|.*_knee_link|.*_ankle_pitch_link|.*_shoulder_.*_link|.*_elbow_link|.*_wrist_.*_link)$"
"""Robot bodies whose floor contact is penalized (everything above the ankle-roll link)."""


def g1_granular_task(
    contact_model: ContactModelName = "rft3d", terrain: TerrainName = "flat", play: bool = False
) -> GranularTaskCfg:
    """Return the task config for one contact model and one terrain ("flat", "rough" or "deep")."""
    terrains = {"flat": flat_sand_terrain, "rough": rough_sand_terrain, "deep": deep_sand_terrain}
    material = MaterialRangeCfg()
    if terrain == "deep":
        # Deep loose bed: low internal friction (spec 1.4: loose sand / poppy seeds).
        material = replace(material, mu_int=(0.1, 0.4))
    return GranularTaskCfg(
        contact_model=contact_model,
        terrain=terrains[terrain](),
        material=material,
        play=play,
    )


def _sensors() -> tuple[ContactSensorCfg, ...]:
    """Foot-floor net force (for contact signals) and non-foot floor contact (penalty)."""
    floor = ContactMatch(mode="body", pattern=SAND_FLOOR_BODY)
    feet = ContactSensorCfg(
        name=FEET_FLOOR_SENSOR,
        primary=ContactMatch(mode="body", pattern=f"^({'|'.join(FOOT_BODIES)})$", entity="robot"),
        secondary=floor,
        fields=("found", "force"),
        reduce="netforce",
        num_slots=1,
    )
    undesired = ContactSensorCfg(
        name="undesired_floor_contact",
        primary=ContactMatch(mode="body", pattern=_UNDESIRED_BODIES, entity="robot"),
        secondary=floor,
        fields=("found",),
        reduce="none",
        num_slots=1,
    )
    return (feet, undesired)


def _scene(task: GranularTaskCfg, num_envs: int) -> SceneCfg:
    """G1 + mocap hard floor; the feet skip the floor only for granular models without it."""
    feet_collide = task.contact_model == "rigid" or task.terrain.floor.enabled
    return SceneCfg(
        num_envs=num_envs,
        terrain=None,
        entities={"robot": get_g1_robot_cfg()},
        sensors=_sensors(),
        spec_fn=partial(add_sand_floor, feet_collide=feet_collide),
        extent=2.0,
    )


def _command(task: GranularTaskCfg) -> UniformVelocityCommandCfg:
    """Twist command with GM-Loco's initial ranges: a yaw target for every env, or mjlab's heading envs."""
    ranges = UniformVelocityCommandCfg.Ranges(lin_vel_x=(-1.0, 1.0), lin_vel_y=(-0.5, 0.5), ang_vel_z=(-0.5, 0.5))
    common = {
        "entity_name": "robot",
        "resampling_time_range": (3.0, 8.0),
        "rel_standing_envs": 0.1,
        "rel_forward_envs": 0.2,
        "debug_vis": False,
    }
    if task.yaw_command == "yaw_target":
        return YawTargetVelocityCommandCfg(
            **common, rel_heading_envs=0.0, heading_stiffness=task.heading_stiffness, ranges=ranges
        )
    ranges.heading = (-math.pi, math.pi)
    return UniformVelocityCommandCfg(
        **common, rel_heading_envs=0.3, heading_command=True, heading_control_stiffness=0.5, ranges=ranges
    )


NJMAX = 400
"""Constraint rows per world. On the deep sand floor a stance foot, a shin and a falling torso can need 300-360 rows;
a world past this drops its rows (MuJoCo Warp's "nefc overflow") and may blow up, which ``physics_diverged`` catches."""


def _terminations(task: GranularTaskCfg) -> dict[str, TerminationTermCfg]:
    """Time out, falling over (70 deg), the pelvis sinking below 0.3 m above the sand, or diverged physics.

    The last resets a world whose simulation blew up (non-finite, or faster than any G1 motion) before its state
    reaches the observations (and through the observation normalizer, every parameter of the policy).
    """
    return {
        "time_out": TerminationTermCfg(func=vel_mdp.time_out, time_out=True),
        "fell_over": TerminationTermCfg(func=vel_mdp.bad_orientation, params={"limit_angle": math.radians(70.0)}),
        "base_too_low": TerminationTermCfg(func=mdp.base_height_below, params={"min_height": 0.3}),
        "physics_diverged": TerminationTermCfg(func=mdp.physics_diverged),
    }


def make_g1_granular_env_cfg(
    task: GranularTaskCfg, num_envs: int = 4096, history_length: int = 0
) -> ManagerBasedRlEnvCfg:
    """Build the mjlab env config of ``num_envs`` envs: 50 Hz policy (decimation 4) over 200 Hz physics.

    ``history_length`` > 0 adds the ``history`` observation group ``[num_envs, N, 96]`` that the VAE teacher's
    encoder and the TCN student read (see :func:`make_observations_cfg`).
    """
    rewards = make_rewards_cfg(task)
    return ManagerBasedRlEnvCfg(
        scene=_scene(task, num_envs),
        observations=make_observations_cfg(task, history_length),
        actions={
            "joint_pos": JointPositionActionCfg(
                entity_name="robot", actuator_names=(".*",), scale=task.action_scale, use_default_offset=True
            )
        },
        commands={"twist": _command(task)},
        events=make_events_cfg(task),
        rewards=rewards,
        terminations=_terminations(task),
        curriculum=make_curriculum_cfg(task, rewards),
        viewer=ViewerConfig(
            origin_type=ViewerConfig.OriginType.ASSET_BODY,
            entity_name="robot",
            body_name="torso_link",
            distance=3.0,
        ),
        sim=SimulationCfg(
            njmax=NJMAX,
            contact_sensor_maxmatch=64,
            mujoco=MujocoCfg(timestep=0.005, iterations=10, ls_iterations=20, ccd_iterations=50),
        ),
        decimation=4,
        episode_length_s=task.episode_length_s,
    )
