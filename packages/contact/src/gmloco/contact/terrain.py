# SPDX-License-Identifier: Apache-2.0
"""Granular terrain: free-surface height field z_s(x, y) and a material that varies along x.

Depth convention (project choice): an element's depth is measured vertically, d = z_s(x, y) - p_z, below the
local surface height at the element's own (x, y). This is exact on flat ground and is the natural extension
of RFT's hydrostatic-like depth scaling to gentle relief; on slopes it differs from the distance along the
surface normal by a factor cos(slope) (< 1.5 % below 10 degrees).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from gmloco.contact.materials import MaterialCfg

__all__ = [
    "TerrainCfg",
    "terrain_flat",
    "terrain_height",
    "terrain_material",
    "terrain_sinusoid",
    "terrain_tiled_levels",
    "terrain_transition",
]

HEIGHT_KINDS: dict[str, int] = {"flat": 0, "sinusoid": 1, "grid": 2}
"""Integer codes of the height-field kinds used by the kernels."""


@dataclass(frozen=True)
class TerrainCfg:
    """Free-surface height field and optional position-dependent material of the granular bed."""

    height: Literal["flat", "sinusoid", "grid"] = "flat"
    """Height-field kind."""
    surface_z: float = 0.0
    """Mean free-surface height z0 [m] (all kinds add it)."""
    amplitude: tuple[float, float] = (0.0, 0.0)
    """Sinusoid amplitudes (a_x, a_y) [m]: z_s = z0 + a_x sin(2 pi x / l_x) + a_y sin(2 pi y / l_y)."""
    wavelength: tuple[float, float] = (1.0, 1.0)
    """Sinusoid wavelengths (l_x, l_y) [m]."""
    grid: tuple[tuple[float, ...], ...] = ((0.0,),)
    """Grid heights above z0 [m], indexed [iy][ix]; bilinear between nodes, clamped outside."""
    grid_origin: tuple[float, float] = (0.0, 0.0)
    """World (x, y) of grid node [0][0] [m]."""
    grid_spacing: float = 1.0
    """Distance between grid nodes [m]."""
    materials: tuple[MaterialCfg, ...] = ()
    """Materials along x; empty = every world uses its own (domain-randomized) material."""
    material_x_edges: tuple[float, ...] = ()
    """World x of the transitions between consecutive materials [m] (len(materials) - 1 values, increasing)."""
    material_blend: float = 0.0
    """Width of the linear blend of (rho_c, mu_int, mu_surf) across each edge [m]; 0 = sharp."""

    def __post_init__(self) -> None:
        """Validate shapes and ranges."""
        if self.height not in HEIGHT_KINDS:
            raise ValueError(f"height={self.height!r}: expected one of {sorted(HEIGHT_KINDS)}")
        if min(self.wavelength) <= 0.0 or self.grid_spacing <= 0.0 or self.material_blend < 0.0:
            raise ValueError("wavelength [m] and grid_spacing [m] must be > 0, material_blend [m] >= 0")
        grid = np.asarray(self.grid, dtype=np.float64)
        if grid.ndim != 2 or not np.all(np.isfinite(grid)):
            raise ValueError(f"grid: need a finite 2D table of heights [m], got shape {grid.shape}")
        if self.materials and len(self.material_x_edges) != len(self.materials) - 1:
            raise ValueError("material_x_edges: need len(materials) - 1 edges [m]")
        if np.any(np.diff(self.material_x_edges) <= 0.0):
            raise ValueError("material_x_edges [m] must increase")

    @property
    def grid_array(self) -> np.ndarray:
        """Grid heights as a float64 array [ny, nx] [m]."""
        return np.asarray(self.grid, dtype=np.float64)

    @property
    def material_table(self) -> np.ndarray:
        """Rows (rho_c [kg/m^3], mu_int [-], mu_surf [-]) of the terrain materials, [M, 3]."""
        return np.array([[m.rho_c, m.mu_int, m.mu_surf] for m in self.materials], dtype=np.float64).reshape(-1, 3)


def terrain_flat(surface_z: float = 0.0) -> TerrainCfg:
    """Return a flat bed with its free surface at ``surface_z`` [m]."""
    return TerrainCfg(surface_z=surface_z)


def terrain_sinusoid(
    amplitude: tuple[float, float], wavelength: tuple[float, float], surface_z: float = 0.0
) -> TerrainCfg:
    """Return a sinusoidal bed z_s = z0 + a_x sin(2 pi x / l_x) + a_y sin(2 pi y / l_y) [m]."""
    return TerrainCfg(height="sinusoid", surface_z=surface_z, amplitude=amplitude, wavelength=wavelength)


def terrain_tiled_levels(
    levels: np.ndarray, tile_size: float, origin: tuple[float, float] = (0.0, 0.0), nodes_per_tile: int = 8
) -> TerrainCfg:
    """Return a grid terrain of flat square tiles, tile [iy, ix] at height ``levels[iy, ix]`` [m].

    Heights are sampled at ``nodes_per_tile`` nodes per tile edge, so the step between tiles is a ramp one
    node spacing wide (tile_size / nodes_per_tile).
    """
    levels = np.atleast_2d(np.asarray(levels, dtype=np.float64))
    ny, nx = levels.shape
    spacing = tile_size / nodes_per_tile
    iy = np.minimum((np.arange(ny * nodes_per_tile) + 0.5) // nodes_per_tile, ny - 1).astype(int)
    ix = np.minimum((np.arange(nx * nodes_per_tile) + 0.5) // nodes_per_tile, nx - 1).astype(int)
    grid = levels[iy][:, ix]
    return TerrainCfg(
        height="grid",
        grid=tuple(map(tuple, grid.tolist())),
        grid_origin=(origin[0] + 0.5 * spacing, origin[1] + 0.5 * spacing),
        grid_spacing=spacing,
    )


def terrain_transition(
    materials: tuple[MaterialCfg, ...], x_edges: tuple[float, ...], blend: float = 0.0, base: TerrainCfg | None = None
) -> TerrainCfg:
    """Return ``base`` (default flat) with materials changing along x, e.g. basalt -> dry sand -> poppy seed."""
    base = base or TerrainCfg()
    return TerrainCfg(
        **{**base.__dict__, "materials": tuple(materials), "material_x_edges": tuple(x_edges), "material_blend": blend}
    )


def terrain_height(cfg: TerrainCfg, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Return z_s(x, y) [m] (float64 reference of the kernel's height function)."""
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    if cfg.height == "flat":
        return np.full(np.broadcast(x, y).shape, cfg.surface_z)
    if cfg.height == "sinusoid":
        ax, ay = cfg.amplitude
        lx, ly = cfg.wavelength
        return cfg.surface_z + ax * np.sin(2 * np.pi * x / lx) + ay * np.sin(2 * np.pi * y / ly)
    grid = cfg.grid_array
    ny, nx = grid.shape
    gx = np.clip((x - cfg.grid_origin[0]) / cfg.grid_spacing, 0.0, nx - 1)
    gy = np.clip((y - cfg.grid_origin[1]) / cfg.grid_spacing, 0.0, ny - 1)
    ix0, iy0 = (
        np.minimum(np.floor(gx).astype(int), max(nx - 2, 0)),
        np.minimum(np.floor(gy).astype(int), max(ny - 2, 0)),
    )
    ix1, iy1 = np.minimum(ix0 + 1, nx - 1), np.minimum(iy0 + 1, ny - 1)
    tx, ty = gx - ix0, gy - iy0
    z0 = grid[iy0, ix0] * (1 - tx) + grid[iy0, ix1] * tx
    z1 = grid[iy1, ix0] * (1 - tx) + grid[iy1, ix1] * tx
    return cfg.surface_z + z0 * (1 - ty) + z1 * ty


def terrain_material(cfg: TerrainCfg, x: np.ndarray) -> np.ndarray:
    """Return (rho_c, mu_int, mu_surf) at world x, [..., 3] (linear blend of width ``material_blend``)."""
    table = cfg.material_table
    x = np.asarray(x, dtype=np.float64)[..., None]
    out = np.broadcast_to(table[0], (*x.shape[:-1], 3)).copy()
    for j, edge in enumerate(cfg.material_x_edges):
        if cfg.material_blend > 0.0:
            s = np.clip((x - edge) / cfg.material_blend + 0.5, 0.0, 1.0)
        else:
            s = (x >= edge).astype(np.float64)
        out += s * (table[j + 1] - table[j])
    return out
