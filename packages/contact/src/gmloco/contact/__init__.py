# SPDX-License-Identifier: Apache-2.0
"""Granular foot-contact models (3D-RFT, Heuristic-RFT, jammed-cone RFT, rigid) as batched Warp kernels.

The float64 numpy reference lives in :mod:`gmloco.contact.reference`.
"""

from gmloco.contact.coefficients import RFT2D_COEFFS, RFT3D_COEFFS, load_rft3d_coeffs
from gmloco.contact.colliders import ColliderBoxCfg, ColliderPoints, box_collider, g1_foot_box_cfg, g1_foot_collider
from gmloco.contact.config import (
    AtRestMode,
    ContactConeMultiCfg,
    ContactConeSingleCfg,
    ContactHeuristicRFTCfg,
    ContactModelCfg,
    ContactRFT3DCfg,
    ContactRigidCfg,
    RftExtensionsCfg,
)
from gmloco.contact.materials import (
    DR_RANGES_CODE,
    DR_RANGES_PAPER,
    MATERIAL_PRESETS,
    DrRanges,
    MaterialCfg,
    eta,
    xi_max,
    xi_n,
)
from gmloco.contact.model_base import ContactModel
from gmloco.contact.models import (
    ContactConeMulti,
    ContactConeSingle,
    ContactHeuristicRFT,
    ContactRFT3D,
    ContactRigid,
    make_contact_model,
)
from gmloco.contact.terrain import (
    TerrainCfg,
    terrain_flat,
    terrain_sinusoid,
    terrain_tiled_levels,
    terrain_transition,
)

__all__ = [
    "DR_RANGES_CODE",
    "DR_RANGES_PAPER",
    "MATERIAL_PRESETS",
    "RFT2D_COEFFS",
    "RFT3D_COEFFS",
    "AtRestMode",
    "ColliderBoxCfg",
    "ColliderPoints",
    "ContactConeMulti",
    "ContactConeMultiCfg",
    "ContactConeSingle",
    "ContactConeSingleCfg",
    "ContactHeuristicRFT",
    "ContactHeuristicRFTCfg",
    "ContactModel",
    "ContactModelCfg",
    "ContactRFT3D",
    "ContactRFT3DCfg",
    "ContactRigid",
    "ContactRigidCfg",
    "DrRanges",
    "MaterialCfg",
    "RftExtensionsCfg",
    "TerrainCfg",
    "box_collider",
    "eta",
    "g1_foot_box_cfg",
    "g1_foot_collider",
    "load_rft3d_coeffs",
    "make_contact_model",
    "terrain_flat",
    "terrain_sinusoid",
    "terrain_tiled_levels",
    "terrain_transition",
    "xi_max",
    "xi_n",
]
