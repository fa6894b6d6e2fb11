# SPDX-License-Identifier: Apache-2.0
"""The yaw-target heading rule of policies trained with ``yaw_command="yaw_target"`` (numpy, for runners).

Such a policy never saw the raw yaw-rate command. In training (``gmloco.train.mdp.commands``) a yaw target
psi_target snaps to the robot's heading psi on the first policy step of an episode, integrates the commanded w_z
by one policy period after every step, and re-snaps to psi when |wrap(psi_target - psi)| passes pi/2; the policy
observes ``w_z_obs = clip(w_z + k * wrap(psi_target - psi), ang_vel_z range)`` with k the metadata's
``heading_stiffness``. :class:`YawTargetCommand` replays that rule step by step, so an evaluation or a robot
runner feeds the policy what it was trained on. Policies trained with ``"heading_envs"`` see w_z directly
(:meth:`YawTargetCfg.from_metadata` returns None for them).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gmloco.deploy.export.metadata import PolicyMetadata

__all__ = ["RESNAP_ERROR", "YawTargetCfg", "YawTargetCommand", "corrected_yaw_rate", "wrap_to_pi"]

RESNAP_ERROR = math.pi / 2
"""Heading error beyond which the yaw target re-snaps to the heading [rad] (GM-Loco's code, ``CommandSpec``)."""


def wrap_to_pi(angle: np.ndarray) -> np.ndarray:
    """Wrap angles [rad] to [-pi, pi)."""
    return np.mod(np.asarray(angle, dtype=np.float64) + math.pi, 2.0 * math.pi) - math.pi


def corrected_yaw_rate(
    yaw_rate: np.ndarray, yaw_error: np.ndarray, stiffness: float, limits: Sequence[float]
) -> np.ndarray:
    """Return the observed yaw-rate command ``clip(w_z + k * e_psi, limits)`` [rad/s], shape of ``yaw_rate``.

    Args:
        yaw_rate: Commanded yaw rate w_z [rad/s].
        yaw_error: Wrapped heading error psi_target - psi [rad].
        stiffness: k [1/s]; 0 leaves the command unchanged (but clipped).
        limits: Range of the yaw-rate command [rad/s].
    """
    return np.clip(np.asarray(yaw_rate) + stiffness * np.asarray(yaw_error), limits[0], limits[1])


@dataclass(frozen=True)
class YawTargetCfg:
    """The heading rule a ``yaw_target`` policy was trained with."""

    stiffness: float
    """k of the correction w_z + k * e_psi [1/s]."""
    limits: tuple[float, float]
    """Clip range of the observed yaw-rate command [rad/s]: the widest trained range (the last curriculum stage's)."""
    policy_dt: float
    """Policy period over which the yaw target integrates w_z [s]."""
    resnap_error: float = RESNAP_ERROR
    """|e_psi| beyond which the target re-snaps to the heading [rad]."""

    @classmethod
    def from_metadata(cls, meta: PolicyMetadata) -> YawTargetCfg | None:
        """The rule of a ``yaw_target`` policy from its metadata; None for ``heading_envs`` (w_z seen directly)."""
        cmd = meta.command
        if cmd.yaw_command != "yaw_target":
            return None
        limits = cmd.stages[-1]["ang_vel_z"] if cmd.stages else cmd.ang_vel_z
        return cls(float(cmd.heading_stiffness), (float(limits[0]), float(limits[1])), float(meta.timing.policy_dt))


class YawTargetCommand:
    """Per-env yaw targets and the observed yaw-rate command of a ``yaw_target`` policy (see the module docstring)."""

    def __init__(self, cfg: YawTargetCfg, num_envs: int) -> None:
        """Allocate the targets; every env snaps to its heading on its first step."""
        self.cfg = cfg
        self.yaw_target = np.zeros(num_envs)
        """Heading each env should hold [rad], ``[num_envs]``."""
        self.yaw_error = np.zeros(num_envs)
        """wrap(yaw_target - heading) of the last step [rad], ``[num_envs]``."""
        self._snap = np.ones(num_envs, dtype=bool)

    def reset(self, env_ids: Sequence[int] | np.ndarray | None = None) -> None:
        """Snap the targets of ``env_ids`` (all if None) to their heading on their next step."""
        if env_ids is None:
            self._snap[:] = True
        else:
            self._snap[np.asarray(env_ids, dtype=int)] = True

    def step(self, yaw_rate: np.ndarray, heading: np.ndarray) -> np.ndarray:
        """One policy step: return the observed w_z [rad/s] ``[num_envs]``, then integrate the targets by w_z dt.

        Args:
            yaw_rate: Commanded yaw rate w_z [rad/s], ``[num_envs]``.
            heading: Robot heading psi (yaw of the base) [rad], ``[num_envs]``.
        """
        yaw_rate = np.asarray(yaw_rate, dtype=np.float64).reshape(self.yaw_target.shape)
        heading = np.asarray(heading, dtype=np.float64).reshape(self.yaw_target.shape)
        if not np.all(np.isfinite(heading)):
            raise ValueError(f"heading must be finite [rad], got {heading}")
        self.yaw_target = np.where(self._snap, heading, self.yaw_target)
        self._snap[:] = False
        err = wrap_to_pi(self.yaw_target - heading)
        lost = np.abs(err) > self.cfg.resnap_error
        self.yaw_target = np.where(lost, heading, self.yaw_target)
        self.yaw_error = np.where(lost, 0.0, err)
        observed = corrected_yaw_rate(yaw_rate, self.yaw_error, self.cfg.stiffness, self.cfg.limits)
        self.yaw_target = wrap_to_pi(self.yaw_target + yaw_rate * self.cfg.policy_dt)
        return observed
