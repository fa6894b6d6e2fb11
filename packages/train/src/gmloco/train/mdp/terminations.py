# SPDX-License-Identifier: Apache-2.0
"""Termination terms of the granular task."""

from __future__ import annotations

from typing import TYPE_CHECKING

import torch
from mjlab.managers.scene_entity_config import SceneEntityCfg
from mjlab.utils.nan_guard import NanGuard

from gmloco.train.sand import get_sand

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv

__all__ = ["MAX_PHYSICAL_SPEED", "base_height_below", "physics_diverged", "roll_pitch_exceeds"]

MAX_PHYSICAL_SPEED = 200.0
"""Largest |qvel| component of a G1 world whose simulation has not diverged [rad/s or m/s]: over 5x the fastest
joint's velocity limit (37 rad/s); a fall stays far below it."""


def physics_diverged(env: ManagerBasedRlEnv, max_speed: float = MAX_PHYSICAL_SPEED) -> torch.Tensor:
    """True where the physics state is non-finite or any generalized velocity exceeds ``max_speed``.

    A world that overflows its constraint rows can blow up without turning NaN at once; its rewards (joint
    acceleration, energy) then reach 1e10 and wreck the critic. Ending it here resets it before its next observation.
    """
    data = env.sim.data
    return NanGuard.detect_nans(data) | (torch.abs(data.qvel) > max_speed).any(dim=-1)


_ROBOT = SceneEntityCfg("robot")


def base_height_below(env: ManagerBasedRlEnv, min_height: float, asset_cfg: SceneEntityCfg = _ROBOT) -> torch.Tensor:
    """True where the pelvis is less than ``min_height`` [m] above the sand free surface."""
    pos = env.scene[asset_cfg.name].data.root_link_pos_w
    return pos[:, 2] - get_sand(env).surface_height(pos[:, 0], pos[:, 1]) < min_height


def roll_pitch_exceeds(env: ManagerBasedRlEnv, limit: float, asset_cfg: SceneEntityCfg = _ROBOT) -> torch.Tensor:
    """True where |roll| or |pitch| of the pelvis (ZYX Euler) exceeds ``limit`` [rad]."""
    w, x, y, z = env.scene[asset_cfg.name].data.root_link_quat_w.unbind(-1)
    roll = torch.atan2(2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y))
    pitch = torch.asin(torch.clamp(-2.0 * (x * z - w * y), -1.0, 1.0))
    return (roll.abs() > limit) | (pitch.abs() > limit)
