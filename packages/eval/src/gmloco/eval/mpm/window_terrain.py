# SPDX-License-Identifier: Apache-2.0
"""The paper's MPM terrains as data: layered media along the course, a sinusoidal surface, the sand depth.

A terrain is a function of the position on the course: the surface height z_s(x, y) [m] and the medium at x.
The sand window (:mod:`gmloco.eval.mpm.window`) evaluates both when it (re)fills a column of sand, so a moving
window sees exactly the terrain a full-length bed would have held.

* flat: one medium, surface z = 0;
* rough: z_s = A sin(2 pi x / lambda) sin(2 pi y / lambda) (GM-Loco initialises the rough MPM surface from a
  sinusoid; amplitude and wavelength are project choices, ``MpmTerrainCfg.rough_*``);
* deep: 30 cm of sand with a 20 deg internal friction angle (mu_int = tan 20 deg);
* transition: basalt -> dry sand -> poppy seed, each ``layer_length`` long along the course.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from gmloco.eval.mpm.materials import MpmMaterialCfg, mpm_material

__all__ = ["TERRAIN_NAMES", "MpmTerrainCfg", "terrain_cfg", "terrain_materials", "terrain_surface_height"]


@dataclass(frozen=True)
class MpmTerrainCfg:
    """One evaluation terrain on MPM sand: its media along the course, depth and surface (``terrain_cfg`` names them)."""

    name: str
    """Label in tables (e.g. ``dry_sand``, ``dry_sand_rough``, ``transition``)."""
    materials: tuple[str, ...]
    """Media along the course (``gmloco.contact.MATERIAL_PRESETS`` names), first at the start."""
    layer_length: float = 3.0
    """Course length of every medium but the last [m] (several media only)."""
    layer_start: float = 1.0
    """Course position x where the second medium begins is ``layer_start + layer_length`` [m]."""
    depth: float = 0.15
    """Sand depth below z = 0 [m]; the rigid floor sits at z = -depth."""
    mu_int: float | None = None
    """Internal friction override [-] (deep sand: tan 20 deg); None = the preset's."""
    rough_amplitude: float = 0.0
    """Amplitude A of the sinusoidal surface [m]; 0 = flat."""
    rough_wavelength: float = 1.0
    """Wavelength lambda of the sinusoidal surface [m]."""


TERRAIN_NAMES = ("basalt", "dry_sand", "poppy_seed", "dry_sand_rough", "dry_sand_deep", "transition")
"""The paper's terrains (``terrain_cfg`` names); any preset name alone is a flat terrain of that medium."""


def terrain_cfg(name: str, depth: float = 0.15) -> MpmTerrainCfg:
    """Return a named terrain: a preset medium (flat), ``<medium>_rough``, ``<medium>_deep`` or ``transition``."""
    # here, not at the top: gmloco.contact pulls Warp; this module imports with numpy alone
    from gmloco.contact import MATERIAL_PRESETS

    if name == "transition":
        return MpmTerrainCfg(name=name, materials=("basalt", "dry_sand", "poppy_seed"), depth=depth)
    base, _, variant = name.rpartition("_") if name.endswith(("_rough", "_deep")) else (name, "", "")
    if base not in MATERIAL_PRESETS:
        raise ValueError(f"unknown terrain {name!r}: use a preset ({sorted(MATERIAL_PRESETS)}), "
                         "'<preset>_rough', '<preset>_deep' or 'transition'")  # fmt: skip
    cfg = MpmTerrainCfg(name=name, materials=(base,), depth=depth)
    if variant == "rough":
        return replace(cfg, rough_amplitude=0.04, rough_wavelength=0.8)
    if variant == "deep":
        return replace(cfg, depth=0.30, mu_int=math.tan(math.radians(20.0)))
    return cfg


def terrain_materials(cfg: MpmTerrainCfg) -> list[MpmMaterialCfg]:
    """MPM parameters of each medium of the terrain (``mu_int`` override applied)."""
    # here, not at the top: gmloco.contact pulls Warp; this module imports with numpy alone
    from gmloco.contact import MATERIAL_PRESETS

    mats = [mpm_material(MATERIAL_PRESETS[m]) for m in cfg.materials]
    return [m if cfg.mu_int is None else replace(m, friction=float(cfg.mu_int)) for m in mats]


def terrain_surface_height(cfg: MpmTerrainCfg, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Surface height z_s(x, y) [m] in lane coordinates (the numpy twin of the window kernel's ``surface_z``)."""
    k = 2.0 * math.pi / cfg.rough_wavelength
    return cfg.rough_amplitude * np.sin(k * np.asarray(x)) * np.sin(k * np.asarray(y))


def terrain_layer(cfg: MpmTerrainCfg, x: np.ndarray) -> np.ndarray:
    """Index of the medium at course position x [m] (numpy twin of the window kernel's ``layer_index``)."""
    n = len(cfg.materials)
    k = np.floor((np.asarray(x) - cfg.layer_start) / cfg.layer_length).astype(int)
    return np.clip(k, 0, n - 1)
