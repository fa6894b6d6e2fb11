# SPDX-License-Identifier: Apache-2.0
"""Imitation terms of the jump task: tracking rewards, phase observations, tracking-loss termination.

Each reward is an exp kernel ``exp(-err^2 / std^2)`` in [0, 1] that peaks (at 1) when the robot is on the
reference (DeepMimic, Peng et al. 2018); the error arithmetic is in ``_``-free pure functions tested by hand.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import torch
from mjlab.utils.lab_api.math import quat_error_magnitude

from gmloco.train.sand import get_sand
from gmloco.train.tasks.g1_jump.assist import get_assist
from gmloco.train.tasks.g1_jump.command import get_jump

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv

__all__ = [
    "assist_scale",
    "base_pos_error",
    "exp_kernel",
    "feet_contact_match",
    "jump_phase",
    "reference_base_error",
    "track_base_ang_vel_exp",
    "track_base_lin_vel_exp",
    "track_base_ori_exp",
    "track_base_pos_exp",
    "track_feet_pos_exp",
    "track_joint_pos_exp",
    "track_joint_vel_exp",
    "tracking_lost",
]


def exp_kernel(sq_error: torch.Tensor, std: float) -> torch.Tensor:
    """Return ``exp(-sq_error / std^2)``: 1 at zero error, e^-1 at one std."""
    return torch.exp(-sq_error / std**2)


def _robot(env: ManagerBasedRlEnv):  # noqa: ANN202
    """The robot entity's data."""
    return env.scene["robot"].data


# Rewards.


def track_joint_pos_exp(env: ManagerBasedRlEnv, std: float) -> torch.Tensor:
    """Kernel of the mean squared joint position error [rad^2], shape [N]."""
    err = _robot(env).joint_pos - get_jump(env).reference("joint_pos")
    return exp_kernel(err.square().mean(dim=-1), std)


def track_joint_vel_exp(env: ManagerBasedRlEnv, std: float) -> torch.Tensor:
    """Kernel of the mean squared joint velocity error [(rad/s)^2], shape [N]."""
    err = _robot(env).joint_vel - get_jump(env).reference("joint_vel")
    return exp_kernel(err.square().mean(dim=-1), std)


def track_base_pos_exp(env: ManagerBasedRlEnv, std: float) -> torch.Tensor:
    """Kernel of the squared base position error [m^2], shape [N]."""
    return exp_kernel(base_pos_error(env).square(), std)


def track_base_ori_exp(env: ManagerBasedRlEnv, std: float) -> torch.Tensor:
    """Kernel of the squared base orientation error angle [rad^2], shape [N]."""
    angle = quat_error_magnitude(_robot(env).root_link_quat_w, get_jump(env).reference("base_quat"))
    return exp_kernel(angle.square(), std)


def track_base_lin_vel_exp(env: ManagerBasedRlEnv, std: float) -> torch.Tensor:
    """Kernel of the squared base linear velocity error [(m/s)^2], world frame, shape [N]."""
    err = _robot(env).root_link_lin_vel_w - get_jump(env).reference("base_lin_vel")
    return exp_kernel(err.square().sum(dim=-1), std)


def track_base_ang_vel_exp(env: ManagerBasedRlEnv, std: float) -> torch.Tensor:
    """Kernel of the squared base angular velocity error [(rad/s)^2], world frame, shape [N]."""
    err = _robot(env).root_link_ang_vel_w - get_jump(env).reference("base_ang_vel")
    return exp_kernel(err.square().sum(dim=-1), std)


def track_feet_pos_exp(env: ManagerBasedRlEnv, std: float) -> torch.Tensor:
    """Kernel of the mean squared sole-site position error over both feet [m^2], shape [N]."""
    jump = get_jump(env)
    feet = _robot(env).site_pos_w[:, jump.feet_site_ids]
    err = feet - jump.reference("feet_pos")
    return exp_kernel(err.square().sum(dim=-1).mean(dim=-1), std)


def feet_contact_match(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Fraction of feet whose contact state (granular or floor force above threshold) matches the reference."""
    contact = get_sand(env).feet.update().in_contact.float()
    return (contact == _ref_contact(env).unsqueeze(-1)).float().mean(dim=-1)


def _ref_contact(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Reference contact state at each env's time (1 on the ground), shape [N]."""
    jump = get_jump(env)
    return (jump.ref.sample("in_contact", jump.time) > 0.5).float()


# Observations.


def jump_phase(env: ManagerBasedRlEnv) -> torch.Tensor:
    """(sin, cos) of pi * phase, shape [N, 2]."""
    return get_jump(env).command


def reference_base_error(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Reference minus actual base position [m], world frame, shape [N, 3] (privileged)."""
    return get_jump(env).reference("base_pos") - _robot(env).root_link_pos_w


def assist_scale(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Current assist scale [-], shape [N, 1] (privileged: the critic sees how much help there is)."""
    return torch.full((env.num_envs, 1), get_assist(env).scale, device=env.device)


# Terminations.


def base_pos_error(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Distance of the base from the reference base [m], shape [N]."""
    return reference_base_error(env).norm(dim=-1)


def tracking_lost(env: ManagerBasedRlEnv, max_error: float) -> torch.Tensor:
    """True where the base is more than ``max_error`` [m] from the reference base."""
    return base_pos_error(env) > max_error
