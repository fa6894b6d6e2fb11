# SPDX-License-Identifier: Apache-2.0
"""Privileged (critic) observation terms read from the granular contact signals."""

from __future__ import annotations

from typing import TYPE_CHECKING

import torch

from gmloco.train.sand import get_sand

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv

__all__ = ["foot_air_time", "foot_contact", "foot_contact_forces", "foot_height", "terrain_eta"]


def foot_height(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Sole height above the sand free surface [m] (negative when sunk), shape [W, 2]."""
    return get_sand(env).feet.update().height


def foot_contact(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Contact state (|F| above threshold) as 0/1, shape [W, 2]."""
    return get_sand(env).feet.update().in_contact.float()


def foot_contact_forces(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Total foot force, sign(F) log(1 + |F|) per component (F in N, world frame), shape [W, 6]."""
    force = get_sand(env).feet.update().force_w.flatten(start_dim=1)
    return torch.sign(force) * torch.log1p(torch.abs(force))


def foot_air_time(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Swing time since the foot left contact [s], shape [W, 2]."""
    return get_sand(env).feet.update().air_time


def terrain_eta(env: ManagerBasedRlEnv) -> torch.Tensor:
    """Normalized granular stiffness eta [-] of the env's material (1 for rigid), shape [W, 1]."""
    return get_sand(env).eta.unsqueeze(-1)
