# SPDX-License-Identifier: Apache-2.0
"""Deploy metadata of a policy trained on the granular G1 task (``gmloco.deploy.export.PolicyMetadata``).

Everything but the joints and the per-term widths comes from the training task config, through the same factories
that built the training env (:func:`make_g1_granular_env_cfg`, :func:`contact_model_cfg`): observation clip and
scale, physics dt and decimation, command ranges, stages and heading rule, contact model and foot collider, terrain, materials
and robot randomization. Joints (order, kp/kd, default pose, action scale) come from the live env
(:func:`policy_metadata_from_env`) or, for a file exported before, from its own older metadata; effort limits
from the G1 actuator table (:mod:`gmloco.deploy.g1`, checked against mjlab's G1 actuator configs).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import asdict
from typing import TYPE_CHECKING, Any

from gmloco.deploy.export.metadata import (
    CommandSpec,
    ContactSpec,
    FootColliderSpec,
    InputLayout,
    JointSpec,
    ObservationSpec,
    ObservationTermSpec,
    PolicyMetadata,
    TimingSpec,
)
from gmloco.deploy.g1 import g1_actuator
from gmloco.train.config import GranularTaskCfg, contact_force_threshold

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv, ManagerBasedRlEnvCfg

__all__ = ["g1_effort_limits", "granular_policy_metadata", "joint_spec", "policy_metadata_from_env"]


def _plain(value: Any) -> Any:
    """JSON-normal form (tuples -> lists), so a metadata object equals its own round trip."""
    return json.loads(json.dumps(value))


def g1_effort_limits(joint_names: Sequence[str]) -> list[float]:
    """Return the actuator torque limit of each joint [N m] from the G1 actuator table (:mod:`gmloco.deploy.g1`).

    Raises:
        ValueError: If a name is not a G1 29-DoF joint.
    """
    try:
        return [g1_actuator(name).effort_limit for name in joint_names]
    except KeyError as err:
        raise ValueError(f"effort limits: {err.args[0]}") from None


def joint_spec(
    names: Sequence[str],
    stiffness: Sequence[float],
    damping: Sequence[float],
    default_pos: Sequence[float],
    action_scale: Sequence[float] | float,
) -> JointSpec:
    """Return the joints block (action order), a scalar action scale broadcast and G1 effort limits added."""
    scale = [float(action_scale)] * len(names) if isinstance(action_scale, int | float) else action_scale
    return JointSpec(
        names=list(names),
        stiffness=[float(k) for k in stiffness],
        damping=[float(d) for d in damping],
        default_pos=[float(q) for q in default_pos],
        action_scale=[float(s) for s in scale],
        effort_limit=g1_effort_limits(names),
    )


def _observation_spec(
    env_cfg: ManagerBasedRlEnvCfg, term_dims: Sequence[int], layout: InputLayout, history_length: int
) -> ObservationSpec:
    """Actor terms in order with the training env's clip and scale and the given per-frame widths."""
    from gmloco.train.tasks.g1_granular.observations_cfg import ACTOR_TERM_DESCRIPTIONS

    actor = env_cfg.observations["actor"].terms
    if len(actor) != len(term_dims):
        raise ValueError(f"{len(term_dims)} term widths for the {len(actor)} actor terms {list(actor)}.")
    terms = []
    for (name, cfg), dim in zip(actor.items(), term_dims, strict=True):
        scale = 1.0 if cfg.scale is None else _plain(cfg.scale if isinstance(cfg.scale, float) else list(cfg.scale))  # type: ignore[arg-type]
        clip = None if cfg.clip is None else [float(cfg.clip[0]), float(cfg.clip[1])]
        terms.append(ObservationTermSpec(name, int(dim), scale, clip, ACTOR_TERM_DESCRIPTIONS.get(name, "")))
    return ObservationSpec(terms=terms, history_length=history_length, layout=layout)


def _contact_spec(task: GranularTaskCfg) -> ContactSpec:
    """Contact model with the foot collider it samples, terrain, materials and robot randomization trained on."""
    from gmloco.train.contact_models import contact_model_cfg
    from gmloco.train.sand import FOOT_BODIES

    box = contact_model_cfg(task.contact_model, task.foot_faces, task.rft_extensions_file).collider
    collider = FootColliderSpec(
        body_names=list(FOOT_BODIES),
        x_range=list(box.x_range),
        y_range=list(box.y_range),
        z_range=list(box.z_range),
        faces=box.faces,
        resolution=list(box.counts),
    )
    return ContactSpec(
        model=task.contact_model,
        foot_collider=collider,
        contact_force_threshold=contact_force_threshold(task),
        terrain=_plain(asdict(task.terrain)),
        materials=_plain(asdict(task.material)),
        robot_randomization=_plain(asdict(task.robot_dr)),
    )


def _command_spec(task: GranularTaskCfg, env_cfg: ManagerBasedRlEnvCfg) -> CommandSpec:
    """The ``twist`` command's initial ranges, curriculum stages, heading rule and meaning."""
    from gmloco.train.tasks.g1_granular.rewards_cfg import command_stages

    cmd = env_cfg.commands["twist"]
    r = cmd.ranges  # type: ignore[attr-defined]
    if task.yaw_command == "yaw_target":
        k = float(task.heading_stiffness)
        how = (
            f"the observed omega_z is clip(omega_z + {k:g} * wrap(yaw_target - yaw), ang_vel_z range), where yaw_target "
            "integrates the commanded omega_z every policy step and snaps to the heading at reset and when the error "
            "passes pi/2; a runner applies the same correction"
        )
    else:
        k = float(cmd.heading_control_stiffness)  # type: ignore[attr-defined]
        how = (
            f"omega_z = clip({k:g} * wrap(heading - yaw)) for the heading-commanded envs in training; a runner may "
            "command omega_z directly"
        )
    return CommandSpec(
        name="twist",
        lin_vel_x=list(r.lin_vel_x),
        lin_vel_y=list(r.lin_vel_y),
        ang_vel_z=list(r.ang_vel_z),
        yaw_command=task.yaw_command,
        heading_stiffness=k,
        stages=_plain(command_stages(task)) if task.command_curriculum else [],
        description=f"the 'command' term is (v_x [m/s], v_y [m/s], omega_z [rad/s]) in the base yaw frame; {how}",
    )


def granular_policy_metadata(
    task: GranularTaskCfg,
    joints: JointSpec,
    term_dims: Sequence[int],
    *,
    layout: InputLayout,
    history_length: int,
    policy_class: str,
    latent_dim: int = 0,
    run_path: str = "local",
    commit: str = "unknown",
) -> PolicyMetadata:
    """Return the deploy metadata of a policy trained on ``task``.

    Args:
        task: The training task config (not a play-mode or evaluation variant: its terrain, materials and
            randomization are recorded as trained on).
        joints: Joints block (:func:`joint_spec`).
        term_dims: Per-frame width of each actor term, in order.
        layout: ``"frame_and_history"`` (student: ``obs`` + ``history``) or ``"term_stacked"`` (mjlab actor).
        history_length: N, frames the policy sees.
        policy_class: ``"StudentActor"`` or ``"MLPModel"``.
        latent_dim: Size of the ``latent`` output (0: none).
        run_path: Training run identifier.
        commit: Git commit of the training code.
    """
    from gmloco.train.tasks.g1_granular.env_cfgs import make_g1_granular_env_cfg

    env_cfg = make_g1_granular_env_cfg(task, num_envs=1)
    physics_dt = float(env_cfg.sim.mujoco.timestep)
    meta = PolicyMetadata(
        observation=_observation_spec(env_cfg, term_dims, layout, history_length),
        joints=joints,
        timing=TimingSpec(physics_dt, int(env_cfg.decimation), physics_dt * env_cfg.decimation),
        contact=_contact_spec(task),
        command=_command_spec(task, env_cfg),
        policy_class=policy_class,
        latent_dim=latent_dim,
        commit=commit,
        run_path=run_path,
    )
    meta.validate()
    return meta


def policy_metadata_from_env(
    env: ManagerBasedRlEnv,
    task: GranularTaskCfg,
    *,
    layout: InputLayout,
    history_length: int,
    policy_class: str,
    latent_dim: int = 0,
    run_path: str = "local",
    commit: str = "unknown",
) -> PolicyMetadata:
    """Return the metadata with joints and term widths read from a live env built for ``task``.

    Raises:
        ValueError: If the action order differs from the joint order (the joint terms would not follow
            ``joints.names``), or the actor terms differ from the task's.
    """
    from mjlab.rl.exporter_utils import get_base_metadata

    base = get_base_metadata(env, run_path)
    actions = list(env.action_manager.get_term("joint_pos").target_names)  # type: ignore[attr-defined]
    if actions != list(base["joint_names"]):  # type: ignore[arg-type]
        raise ValueError(f"action order {actions} differs from the joint order {base['joint_names']}.")
    joints = joint_spec(actions, base["joint_stiffness"], base["joint_damping"], base["default_joint_pos"],  # type: ignore[arg-type]
                        base["action_scale"])  # type: ignore[arg-type]  # fmt: skip
    om = env.observation_manager
    stacked = max(om.get_term_cfg("actor", om.active_terms["actor"][0]).history_length, 1)  # type: ignore[index]
    dims = [math.prod(d) // stacked for d in om.group_obs_term_dim["actor"]]
    return granular_policy_metadata(
        task, joints, dims, layout=layout, history_length=history_length, policy_class=policy_class,
        latent_dim=latent_dim, run_path=run_path, commit=commit,
    )  # fmt: skip
