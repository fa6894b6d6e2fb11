# SPDX-License-Identifier: Apache-2.0
"""Adapter from :class:`GranularTaskCfg` to ``gmloco.contact`` (the only module that imports it)."""

from __future__ import annotations

from typing import Any

import torch
import warp as wp
from gmloco.train.config import ContactModelName, GranularTaskCfg

__all__ = ["build_contact_model", "contact_model_cfg", "material_eta", "set_model_materials"]

NUM_FEET = 2
"""Feet per robot that carry a granular wrench."""


def contact_model_cfg(name: ContactModelName) -> Any:
    """Return the default ``gmloco.contact`` config of a named contact model."""
    import gmloco.contact as gc

    table = {
        "rft3d": gc.ContactRFT3DCfg,
        "heuristic_rft": gc.ContactHeuristicRFTCfg,
        "cone_multi": gc.ContactConeMultiCfg,
        "cone_single": gc.ContactConeSingleCfg,
        "rigid": gc.ContactRigidCfg,
    }
    return table[name]()


def _contact_terrain(task: GranularTaskCfg) -> Any:
    """Map the sand terrain to ``gmloco.contact.TerrainCfg`` (None: flat surface at z = 0)."""
    terrain = task.terrain
    if terrain.amplitude == 0.0:
        return None
    import gmloco.contact as gc

    return gc.TerrainCfg(amplitude=terrain.amplitude, wavelength=terrain.wavelength)


def build_contact_model(task: GranularTaskCfg, num_envs: int, device: wp.context.Device) -> tuple[Any, bool]:
    """Build the task's contact model for ``num_envs`` worlds; returns ``(model, stateful)``."""
    import gmloco.contact as gc

    cfg = contact_model_cfg(task.contact_model)
    model = gc.make_contact_model(cfg, num_envs, NUM_FEET, str(device), terrain=_contact_terrain(task))
    stateful = bool(getattr(model, "is_stateful", True))
    return model, stateful


def set_model_materials(
    model: Any, rho_c: torch.Tensor, mu_int: torch.Tensor, mu_surf: torch.Tensor, env_ids: torch.Tensor
) -> None:
    """Copy the materials of ``env_ids`` (from full ``[W]`` tensors) into the contact model."""
    model.set_materials(rho_c[env_ids], mu_int[env_ids], mu_surf[env_ids], env_ids=env_ids)


def material_eta(
    model: Any, rho_c: torch.Tensor, mu_int: torch.Tensor, env_ids: torch.Tensor
) -> torch.Tensor:
    """Return the model's normalized stiffness eta [-] of ``env_ids``, shape ``[len(env_ids)]``."""
    del rho_c, mu_int
    return wp.to_torch(model.eta)[env_ids]
