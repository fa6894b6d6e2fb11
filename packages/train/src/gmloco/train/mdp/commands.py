# SPDX-License-Identifier: Apache-2.0
"""Velocity command with a yaw target: (v_x, v_y, w_z) plus a heading that integrates w_z every step.

GM-Loco's public code tracks a yaw target next to the twist: the target integrates the commanded yaw rate every
policy step, is re-snapped to the current heading when the error passes pi/2, and a "track yaw quat" reward of
weight 4 pays for holding it. Here the observed yaw-rate command also carries a proportional correction,
``w_z_obs = clip(w_z + k * wrap(psi_target - psi), w_z range)`` (mjlab's heading control, applied to every env),
so a deployed policy holds its heading under a straight command and turns at the commanded rate on average; the
same rule is part of the policy's deploy contract (``heading_stiffness`` in its metadata).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import torch
from mjlab.tasks.velocity.mdp import UniformVelocityCommand, UniformVelocityCommandCfg
from mjlab.utils.lab_api.math import wrap_to_pi

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv

__all__ = ["YawTargetVelocityCommand", "YawTargetVelocityCommandCfg", "corrected_yaw_rate", "hold_twist"]


def corrected_yaw_rate(
    yaw_rate: torch.Tensor, yaw_error: torch.Tensor, stiffness: float, limits: tuple[float, float]
) -> torch.Tensor:
    """Return the observed yaw-rate command ``clip(w_z + k * e_psi, limits)`` [rad/s], shape of ``yaw_rate``.

    Args:
        yaw_rate: Commanded yaw rate w_z [rad/s].
        yaw_error: Wrapped heading error psi_target - psi [rad].
        stiffness: k [1/s]; 0 leaves the command unchanged.
        limits: Range of the yaw-rate command [rad/s].
    """
    return torch.clamp(yaw_rate + stiffness * yaw_error, min=limits[0], max=limits[1])


class YawTargetVelocityCommand(UniformVelocityCommand):
    """Twist command whose yaw target integrates the commanded yaw rate (see the module docstring)."""

    cfg: YawTargetVelocityCommandCfg

    def __init__(self, cfg: YawTargetVelocityCommandCfg, env: ManagerBasedRlEnv) -> None:
        """Allocate the raw twist, the yaw target and its error."""
        super().__init__(cfg, env)
        self.twist = torch.zeros(self.num_envs, 3, device=self.device)
        """Commanded (v_x, v_y, w_z) before the heading correction [m/s, m/s, rad/s], ``[num_envs, 3]``."""
        self.yaw_target = torch.zeros(self.num_envs, device=self.device)
        """Heading the robot should hold [rad], ``[num_envs]``; integrates w_z."""
        self.yaw_error = torch.zeros(self.num_envs, device=self.device)
        """wrap(yaw_target - heading) [rad], ``[num_envs]``."""
        self._snap = torch.ones(self.num_envs, dtype=torch.bool, device=self.device)
        self._yaw_rate = torch.zeros(self.num_envs, device=self.device)
        self.metrics["error_heading"] = torch.zeros(self.num_envs, device=self.device)

    def set_twist(self, twist: torch.Tensor, env_ids: torch.Tensor | None = None) -> None:
        """Hold a given twist (evaluation): ``twist`` [n, 3] for ``env_ids`` (None: every env)."""
        ids = slice(None) if env_ids is None else env_ids
        self.twist[ids] = twist
        self.vel_command_b[ids] = twist

    def reset(self, env_ids: torch.Tensor | slice | None) -> dict[str, float]:
        """Reset as mjlab does; the yaw target snaps to the heading at the next update (after the reset's forward)."""
        extras = super().reset(env_ids)
        self._snap[env_ids] = True
        return extras

    def _update_metrics(self) -> None:
        """Mjlab's twist errors plus the mean |heading error| over a command period [rad]."""
        super()._update_metrics()
        max_steps = self.cfg.resampling_time_range[1] / self._env.step_dt
        self.metrics["error_heading"] += self.yaw_error.abs() / max_steps

    def _resample_command(self, env_ids: torch.Tensor) -> None:
        """Sample as mjlab does and keep the sample as the raw twist."""
        super()._resample_command(env_ids)
        self.twist[env_ids] = self.vel_command_b[env_ids]

    def _update_command(self, env_ids: torch.Tensor | None) -> None:
        """Apply mjlab's world-frame and standing rules to the raw twist, then the heading correction."""
        self.vel_command_b[:] = self.twist
        super()._update_command(env_ids)
        heading = self.robot.data.heading_w
        self.yaw_target = torch.where(self._snap, heading, self.yaw_target)
        self._snap[:] = False
        err = wrap_to_pi(self.yaw_target - heading)
        lost = err.abs() > self.cfg.resnap_error
        self.yaw_target = torch.where(lost, heading, self.yaw_target)
        self.yaw_error = torch.where(lost, torch.zeros_like(err), err)
        self._yaw_rate = self.vel_command_b[:, 2].clone()
        moving = ~self.is_standing_env
        corrected = corrected_yaw_rate(
            self._yaw_rate, self.yaw_error, self.cfg.heading_stiffness, self.cfg.ranges.ang_vel_z
        )
        self.vel_command_b[:, 2] = torch.where(moving, corrected, self._yaw_rate)

    def compute(self, dt: float | torch.Tensor, env_ids: torch.Tensor | None = None) -> None:
        """Advance timers and commands, then integrate the yaw target by the commanded w_z over ``dt`` [s]."""
        super().compute(dt, env_ids)
        step = self._yaw_rate * dt
        if env_ids is None:
            self.yaw_target = wrap_to_pi(self.yaw_target + step)
        else:
            self.yaw_target[env_ids] = wrap_to_pi(self.yaw_target[env_ids] + step[env_ids])


@dataclass(kw_only=True)
class YawTargetVelocityCommandCfg(UniformVelocityCommandCfg):
    """Config of :class:`YawTargetVelocityCommand` (mjlab's heading envs are off: every env holds a yaw target)."""

    heading_stiffness: float = 1.0
    """k of the observed yaw-rate correction w_z + k * e_psi [1/s]; 0: the policy sees the raw w_z."""
    resnap_error: float = math.pi / 2
    """Heading error beyond which the target re-snaps to the current heading [rad] (GM-Loco's code: pi/2)."""

    def build(self, env: ManagerBasedRlEnv) -> YawTargetVelocityCommand:
        """Build the command term."""
        return YawTargetVelocityCommand(self, env)


def hold_twist(term: UniformVelocityCommand, twist: torch.Tensor) -> None:
    """Hold ``twist`` [num_envs, 3] on a twist command term (evaluation with fixed commands).

    A :class:`YawTargetVelocityCommand` keeps it as its raw twist, so its heading correction still applies; a plain
    mjlab term gets it written to its command buffer.
    """
    if isinstance(term, YawTargetVelocityCommand):
        term.set_twist(twist)
    else:
        term.vel_command_b[:] = twist
