# SPDX-License-Identifier: Apache-2.0
"""Newton implicit-MPM scenes: material mapping, sand bed, box and plate intrusion (Newton imported lazily)."""

from gmloco.eval.mpm.bed import SandBedCfg, bed_particle_positions, emit_sand_bed
from gmloco.eval.mpm.box_scene import MpmBoxScene, MpmBoxSceneCfg, MpmSolverCfg
from gmloco.eval.mpm.materials import GranularMaterial, MpmMaterialCfg, apply_mpm_material, mpm_material

__all__ = [
    "GranularMaterial",
    "MpmBoxScene",
    "MpmBoxSceneCfg",
    "MpmMaterialCfg",
    "MpmSolverCfg",
    "SandBedCfg",
    "apply_mpm_material",
    "bed_particle_positions",
    "emit_sand_bed",
    "mpm_material",
]
