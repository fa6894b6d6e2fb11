# SPDX-License-Identifier: Apache-2.0
"""Termination terms of the granular task."""

from __future__ import annotations

from typing import TYPE_CHECKING

import torch
from mjlab.managers.scene_entity_config import SceneEntityCfg

from gmloco.train.sand import get_sand

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv

__all__ = ["base_height_below", "roll_pitch_exceeds"]

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
