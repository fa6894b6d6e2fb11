# SPDX-License-Identifier: Apache-2.0
"""Termination terms of the granular task."""

from __future__ import annotations

from typing import TYPE_CHECKING

import torch
from gmloco.train.sand import get_sand
from mjlab.managers.scene_entity_config import SceneEntityCfg

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv

__all__ = ["base_height_below"]

_ROBOT = SceneEntityCfg("robot")


def base_height_below(
    env: ManagerBasedRlEnv, min_height: float, asset_cfg: SceneEntityCfg = _ROBOT
) -> torch.Tensor:
    """True where the pelvis is less than ``min_height`` [m] above the sand free surface."""
    pos = env.scene[asset_cfg.name].data.root_link_pos_w
    return pos[:, 2] - get_sand(env).surface_height(pos[:, 0], pos[:, 1]) < min_height
