# SPDX-License-Identifier: Apache-2.0
"""GM-Loco reward terms (spec section 4) with Isaac Lab-style names.

Each env-facing term is a thin wrapper over a pure tensor function (``_``-prefixed) so that the
arithmetic is unit-tested on hand-computed cases. Foot signals come from the shared
:class:`~gmloco.train.foot_contact.FootContactTracker` (granular + floor force).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import torch
from mjlab.managers.scene_entity_config import SceneEntityCfg
from mjlab.tasks.velocity.mdp import variable_posture
from mjlab.utils.lab_api.math import quat_apply_inverse, wrap_to_pi, yaw_quat

from gmloco.train.sand import get_sand

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.managers.reward_manager import RewardTermCfg

__all__ = [
    "action_rate_l2",
    "ang_vel_xy_l2",
    "base_height_l2",
    "contact_impulse",
    "energy",
    "feet_air_time",
    "feet_lateral_distance",
    "feet_pitch_diff_l2",
    "feet_pitch_in_contact_l2",
    "feet_pitch_l2",
    "feet_roll_diff_l2",
    "feet_roll_l2",
    "feet_slide",
    "flat_orientation_l2",
    "foot_clearance",
    "foot_clearance_l2",
    "foot_clearance_sinkage_l2",
    "joint_acc_l2",
    "joint_vel_l2",
    "lin_vel_z_l2",
    "no_fly",
    "sinkage_clearance_target",
    "swing_apex_sinkage_at_touchdown",
    "swing_height_at_touchdown",
    "track_ang_vel_z_exp",
    "track_heading_exp",
    "track_lin_vel_xy_exp",
    "track_yaw_target_exp",
    "undesired_contacts",
    "variable_posture_l1",
]

_ROBOT = SceneEntityCfg("robot")


def _command(env: ManagerBasedRlEnv, command_name: str) -> torch.Tensor:
    """Commanded (vx, vy, wz) in the base frame [m/s, m/s, rad/s], shape [W, 3]."""
    command = env.command_manager.get_command(command_name)
    assert command is not None, f"Command '{command_name}' not found."
    return command


# Pure tensor functions (unit-tested).


def _exp_kernel(sq_error: torch.Tensor, std: float) -> torch.Tensor:
    """exp(-e / std^2) for a squared error e."""
    return torch.exp(-sq_error / std**2)


def _wrapped_abs_diff(a: torch.Tensor) -> torch.Tensor:
    """|wrap(a[:, 1] - a[:, 0])| [rad] for per-foot angles a, shape [W, 2] -> [W]."""
    return torch.abs(wrap_to_pi(a[:, 1] - a[:, 0]))


def _single_stance_time(air_time: torch.Tensor, contact_time: torch.Tensor, threshold: float) -> torch.Tensor:
    """Isaac Lab ``feet_air_time_positive_biped``: min time in the current mode, single stance only."""
    in_contact = contact_time > 0.0
    mode_time = torch.where(in_contact, contact_time, air_time)
    single = in_contact.sum(dim=1) == 1
    reward = torch.min(torch.where(single.unsqueeze(-1), mode_time, 0.0), dim=1).values
    return torch.clamp(reward, max=threshold)


def _clearance(
    height: torch.Tensor, speed_xy: torch.Tensor, target: float, std: float, tanh_mult: float
) -> torch.Tensor:
    """exp(-sum_f (h_f - target)^2 tanh(k |v_f,xy|) / std) for feet heights h [m] and speeds [m/s]."""
    return torch.exp(-_clearance_error(height, speed_xy, target, tanh_mult) / std)


def _clearance_error(
    height: torch.Tensor, speed_xy: torch.Tensor, target: float | torch.Tensor, tanh_mult: float
) -> torch.Tensor:
    """sum_f (h_f - target)^2 tanh(k |v_f,xy|) [m^2] for feet heights h [m] and speeds [m/s]; 0 for still feet.

    ``target`` [m] is one height, or one per foot ``[W, 2]``.
    """
    return (torch.square(height - target) * torch.tanh(tanh_mult * speed_xy)).sum(dim=1)


def _lateral_gap_penalty(foot_pos_w: torch.Tensor, root_quat_w: torch.Tensor, min_gap: float) -> torch.Tensor:
    """clip(min_gap - |y_L - y_R|, 0, 0.1) [m] with y in the base yaw frame; foot_pos_w [W, 2, 3]."""
    rel = foot_pos_w[:, 1] - foot_pos_w[:, 0]
    rel_b = quat_apply_inverse(yaw_quat(root_quat_w), rel)
    return torch.clamp(min_gap - torch.abs(rel_b[:, 1]), min=0.0, max=0.1)


def _moving(command: torch.Tensor, threshold: float) -> torch.Tensor:
    """1 where |v_xy cmd| + |w_z cmd| > threshold, else 0, shape [W]."""
    return ((torch.linalg.vector_norm(command[:, :2], dim=1) + command[:, 2].abs()) > threshold).float()


# Tracking.


def track_lin_vel_xy_exp(
    env: ManagerBasedRlEnv, std: float, command_name: str, asset_cfg: SceneEntityCfg = _ROBOT
) -> torch.Tensor:
    """Track the commanded xy velocity in the gravity-aligned (yaw) base frame, exp kernel."""
    data = env.scene[asset_cfg.name].data
    vel_yaw = quat_apply_inverse(yaw_quat(data.root_link_quat_w), data.root_link_lin_vel_w)
    err = torch.sum(torch.square(_command(env, command_name)[:, :2] - vel_yaw[:, :2]), dim=1)
    return _exp_kernel(err, std)


def track_ang_vel_z_exp(
    env: ManagerBasedRlEnv, std: float, command_name: str, asset_cfg: SceneEntityCfg = _ROBOT
) -> torch.Tensor:
    """Track the commanded yaw rate (world z), exp kernel."""
    wz = env.scene[asset_cfg.name].data.root_link_ang_vel_w[:, 2]
    return _exp_kernel(torch.square(_command(env, command_name)[:, 2] - wz), std)


def track_heading_exp(
    env: ManagerBasedRlEnv, std: float, command_name: str, asset_cfg: SceneEntityCfg = _ROBOT
) -> torch.Tensor:
    """Track the heading target of heading-commanded envs, exp kernel (0 for the other envs)."""
    term = env.command_manager.get_term(command_name)
    heading = env.scene[asset_cfg.name].data.heading_w
    err = wrap_to_pi(term.heading_target - heading)  # type: ignore[attr-defined]
    return _exp_kernel(torch.square(err), std) * term.is_heading_env.float()  # type: ignore[attr-defined]


def track_yaw_target_exp(
    env: ManagerBasedRlEnv, std: float, command_name: str, asset_cfg: SceneEntityCfg = _ROBOT
) -> torch.Tensor:
    """Track the yaw target of a :class:`~gmloco.train.mdp.commands.YawTargetVelocityCommand`, exp kernel.

    GM-Loco's "track yaw quat" term (weight 4), in every env: exp(-e_psi^2 / std^2) with e_psi the wrapped heading
    error [rad].
    """
    del asset_cfg  # the command term keeps the error against the robot's heading
    term = env.command_manager.get_term(command_name)
    return _exp_kernel(torch.square(term.yaw_error), std)  # type: ignore[attr-defined]


# Base motion.


def lin_vel_z_l2(env: ManagerBasedRlEnv, asset_cfg: SceneEntityCfg = _ROBOT) -> torch.Tensor:
    """Squared base vertical velocity [m^2/s^2]."""
    return torch.square(env.scene[asset_cfg.name].data.root_link_lin_vel_b[:, 2])


def ang_vel_xy_l2(env: ManagerBasedRlEnv, asset_cfg: SceneEntityCfg = _ROBOT) -> torch.Tensor:
    """Squared base roll/pitch rate [rad^2/s^2]."""
    return torch.sum(torch.square(env.scene[asset_cfg.name].data.root_link_ang_vel_b[:, :2]), dim=1)


def flat_orientation_l2(env: ManagerBasedRlEnv, asset_cfg: SceneEntityCfg = _ROBOT) -> torch.Tensor:
    """Squared xy components of gravity in the base frame [-]."""
    return torch.sum(torch.square(env.scene[asset_cfg.name].data.projected_gravity_b[:, :2]), dim=1)


def base_height_l2(env: ManagerBasedRlEnv, target_height: float, asset_cfg: SceneEntityCfg = _ROBOT) -> torch.Tensor:
    """Squared deviation of the pelvis height above the sand surface from ``target_height`` [m^2]."""
    pos = env.scene[asset_cfg.name].data.root_link_pos_w
    height = pos[:, 2] - get_sand(env).surface_height(pos[:, 0], pos[:, 1])
    return torch.square(height - target_height)


# Joints and actions.


class action_rate_l2:  # noqa: N801 (mjlab term naming)
    """Squared change of the actions of the joints matching ``joint_names`` between env steps."""

    def __init__(self, cfg: RewardTermCfg, env: ManagerBasedRlEnv) -> None:
        from mjlab.utils.lab_api.string import resolve_matching_names

        names = env.action_manager.get_term("joint_pos").target_names  # type: ignore[attr-defined]
        ids, _ = resolve_matching_names(cfg.params["joint_names"], list(names))
        self.ids = torch.tensor(ids, device=env.device)

    def __call__(self, env: ManagerBasedRlEnv, joint_names: tuple[str, ...]) -> torch.Tensor:
        """Sum over the selected joints of (a_t - a_{t-1})^2."""
        del joint_names
        am = env.action_manager
        return torch.sum(torch.square(am.action[:, self.ids] - am.prev_action[:, self.ids]), dim=1)


def energy(env: ManagerBasedRlEnv, asset_cfg: SceneEntityCfg = _ROBOT) -> torch.Tensor:
    """Absolute mechanical joint power sum |tau q_dot| [W]."""
    data = env.scene[asset_cfg.name].data
    return torch.sum(torch.abs(data.qfrc_actuator * data.joint_vel), dim=1)


def joint_vel_l2(env: ManagerBasedRlEnv, asset_cfg: SceneEntityCfg = _ROBOT) -> torch.Tensor:
    """Sum of squared joint velocities [rad^2/s^2]."""
    return torch.sum(torch.square(env.scene[asset_cfg.name].data.joint_vel), dim=1)


def joint_acc_l2(env: ManagerBasedRlEnv, asset_cfg: SceneEntityCfg = _ROBOT) -> torch.Tensor:
    """Sum of squared joint accelerations [rad^2/s^4]."""
    return torch.sum(torch.square(env.scene[asset_cfg.name].data.joint_acc), dim=1)


class variable_posture_l1(variable_posture):  # noqa: N801 (mjlab term naming)
    """L1 pose penalty: mean_j |q_j - q0_j| / std_j with speed-dependent std (mjlab's regimes)."""

    def __call__(  # type: ignore[override]
        self,
        env: ManagerBasedRlEnv,
        std_standing: dict,
        std_walking: dict,
        std_running: dict,
        asset_cfg: SceneEntityCfg,
        command_name: str,
        walking_threshold: float = 0.5,
        running_threshold: float = 1.5,
    ) -> torch.Tensor:
        """Mean normalized absolute deviation from the default pose [-]."""
        del std_standing, std_walking, std_running
        speed = torch.linalg.vector_norm(_command(env, command_name)[:, :2], dim=1)
        speed = speed + _command(env, command_name)[:, 2].abs()
        std = torch.where((speed < walking_threshold).unsqueeze(1), self.std_standing, self.std_walking)
        std = torch.where((speed >= running_threshold).unsqueeze(1), self.std_running, std)
        q = env.scene[asset_cfg.name].data.joint_pos[:, asset_cfg.joint_ids]
        return torch.mean(torch.abs(q - self.default_joint_pos[:, asset_cfg.joint_ids]) / std, dim=1)


# Feet.


def feet_roll_l2(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Sum of squared foot roll angles [rad^2]."""
    return torch.sum(torch.square(get_sand(env).feet.update().roll), dim=1)


def feet_roll_diff_l2(env: ManagerBasedRlEnv) -> torch.Tensor:
    """|wrap(roll_R - roll_L)| [rad] (GM-Loco ``reward_feet_roll_diff``)."""
    return _wrapped_abs_diff(get_sand(env).feet.update().roll)


def feet_pitch_l2(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Sum of squared foot pitch angles [rad^2]."""
    return torch.sum(torch.square(get_sand(env).feet.update().pitch), dim=1)


def feet_pitch_diff_l2(env: ManagerBasedRlEnv) -> torch.Tensor:
    """|wrap(pitch_R - pitch_L)| [rad] (GM-Loco ``reward_feet_pitch_diff``)."""
    return _wrapped_abs_diff(get_sand(env).feet.update().pitch)


def feet_pitch_in_contact_l2(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Squared foot pitch at touchdown only [rad^2] (flat-foot landings)."""
    feet = get_sand(env).feet.update()
    return torch.sum(torch.square(feet.pitch) * feet.first_contact, dim=1)


def feet_air_time(env: ManagerBasedRlEnv, threshold: float, command_name: str) -> torch.Tensor:
    """Single-stance time up to ``threshold`` [s] while a motion is commanded."""
    feet = get_sand(env).feet.update()
    reward = _single_stance_time(feet.air_time, feet.contact_time, threshold)
    return reward * _moving(_command(env, command_name), 0.05)


def no_fly(env: ManagerBasedRlEnv, command_name: str, max_speed: float = 1.5) -> torch.Tensor:
    """1 when both feet are off the ground while the command is slower than ``max_speed`` [m/s]."""
    feet = get_sand(env).feet.update()
    slow = torch.linalg.vector_norm(_command(env, command_name)[:, :2], dim=1) < max_speed
    return (~feet.in_contact.any(dim=1) & slow).float()


def feet_lateral_distance(env: ManagerBasedRlEnv, min_gap: float, asset_cfg: SceneEntityCfg = _ROBOT) -> torch.Tensor:
    """How far the lateral foot gap is below ``min_gap`` [m], clipped to 0.1 m."""
    feet, data = get_sand(env).feet, env.scene[asset_cfg.name].data
    return _lateral_gap_penalty(data.site_pos_w[:, feet.site_ids], data.root_link_quat_w, min_gap)


def feet_slide(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Sum over feet in contact of the horizontal sole speed [m/s]."""
    return torch.sum(get_sand(env).feet.update().slip_speed, dim=1)


def contact_impulse(env: ManagerBasedRlEnv, command_name: str) -> torch.Tensor:
    """Sum of |F| at touchdown [N] while moving (GM-Loco soft landing)."""
    feet = get_sand(env).feet.update()
    return torch.sum(feet.landing_force, dim=1) * _moving(_command(env, command_name), 0.05)


def foot_clearance(env: ManagerBasedRlEnv, target_height: float, std: float, tanh_mult: float) -> torch.Tensor:
    """Swing feet at ``target_height`` [m] above the sand, weighted by tanh of their speed."""
    feet = get_sand(env).feet.update()
    speed = torch.linalg.vector_norm(feet.vel_w[..., :2], dim=-1)
    return _clearance(feet.height, speed, target_height, std, tanh_mult)


def swing_height_at_touchdown(
    env: ManagerBasedRlEnv, target_height: float, command_name: str, relative: bool = True
) -> torch.Tensor:
    """Sum over feet touching down this step of the finished swing's height, clipped to [0, ``target_height``] [m].

    ``relative``: the swing's lift above the lowest point of the stance before it (how far the foot came out of
    its own footprint, what a foot on soft sand needs); otherwise its apex above the free surface. Paid only for
    completed swings while a motion is commanded, so neither standing still nor ending the episode earns it (the
    L2 penalty ``foot_clearance_l2`` at weight -300 taught a teacher to fall early; the exp form pays still feet).
    """
    feet = get_sand(env).feet.update()
    height = feet.last_swing_lift if relative else feet.last_swing_apex
    paid = torch.clamp(height, min=0.0, max=target_height) * feet.first_contact
    return paid.sum(dim=1) * _moving(_command(env, command_name), 0.05)


def foot_clearance_l2(env: ManagerBasedRlEnv, target_height: float, tanh_mult: float) -> torch.Tensor:
    """Speed-weighted squared miss of the swing height ``target_height`` [m] (use with a negative weight).

    The GM-Loco project page's form (foot clearance -2 as an L2 penalty). Unlike the exp form
    :func:`foot_clearance`, it pays nothing for feet that stay still, so standing is not rewarded.
    """
    feet = get_sand(env).feet.update()
    speed = torch.linalg.vector_norm(feet.vel_w[..., :2], dim=-1)
    return _clearance_error(feet.height, speed, target_height, tanh_mult)


def sinkage_clearance_target(
    sinkage: torch.Tensor, target_height: float, sinkage_gain: float, max_height: float
) -> torch.Tensor:
    """Return the swing height target min(h_0 + g max(s, 0), h_max) [m] for footprint depths s [m], shape of s.

    The GM-Loco project page shows the swing apex rising from ~9 cm on stiff ground to ~16 cm on soft ground; a
    target that grows with how deep the foot's last stance sank asks for that without a material label (a foot
    that sank s must first climb s out of its footprint, and soft sand drags the foot box while it is buried).
    """
    return torch.clamp(target_height + sinkage_gain * torch.clamp(sinkage, min=0.0), max=max_height)


def foot_clearance_sinkage_l2(
    env: ManagerBasedRlEnv, target_height: float, sinkage_gain: float, max_height: float, tanh_mult: float
) -> torch.Tensor:
    """Speed-weighted squared miss of a swing target that grows with the footprint's depth (negative weight).

    As :func:`foot_clearance_l2`, with the target of each foot :func:`sinkage_clearance_target` of the depth of its
    current (in the air: last) stance below the free surface, ``-stance_low`` [m].
    """
    feet = get_sand(env).feet.update()
    speed = torch.linalg.vector_norm(feet.vel_w[..., :2], dim=-1)
    target = sinkage_clearance_target(-feet.stance_low, target_height, sinkage_gain, max_height)
    return _clearance_error(feet.height, speed, target, tanh_mult)


def _sinkage_lift_paid(
    apex: torch.Tensor, lift: torch.Tensor, target_height: float, sinkage_gain: float, max_height: float
) -> torch.Tensor:
    """Lift of a finished swing [m], clipped to [0, s + target(s)] with s = lift - apex the footprint's depth.

    The cap is the lift that puts the apex at :func:`sinkage_clearance_target` above the surface, so the payment
    grows until then: on stiff ground (s ~ 0) up to h_0, from a 7 cm footprint up to 7 cm + h_0 + g 7 cm. The
    fixed 12 cm lift cap of :func:`swing_height_at_touchdown` instead stops paying at a 5 cm apex there.
    """
    sinkage = torch.clamp(lift - apex, min=0.0)
    cap = sinkage + sinkage_clearance_target(sinkage, target_height, sinkage_gain, max_height)
    return torch.minimum(torch.clamp(lift, min=0.0), cap)


def swing_apex_sinkage_at_touchdown(
    env: ManagerBasedRlEnv, target_height: float, sinkage_gain: float, max_height: float, command_name: str
) -> torch.Tensor:
    """Sum over feet touching down this step of the finished swing's lift, capped at the sinkage-aware target [m].

    :func:`_sinkage_lift_paid` of the swing's apex and lift (``last_swing_apex``, ``last_swing_lift``); paid only
    for completed swings while a motion is commanded, as :func:`swing_height_at_touchdown`.
    """
    feet = get_sand(env).feet.update()
    paid = _sinkage_lift_paid(feet.last_swing_apex, feet.last_swing_lift, target_height, sinkage_gain, max_height)
    return (paid * feet.first_contact).sum(dim=1) * _moving(_command(env, command_name), 0.05)


def undesired_contacts(env: ManagerBasedRlEnv, sensor_name: str) -> torch.Tensor:
    """Number of non-foot bodies touching the floor."""
    found = env.scene[sensor_name].data.found
    return (found > 0).float().sum(dim=1)
