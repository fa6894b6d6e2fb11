# SPDX-License-Identifier: Apache-2.0
"""Terrain height fields and material fields (float64 reference of the kernel functions)."""

from __future__ import annotations

import numpy as np

from gmloco.contact import MATERIAL_PRESETS, TerrainCfg, terrain_sinusoid, terrain_tiled_levels, terrain_transition
from gmloco.contact.terrain import terrain_height, terrain_material


def test_sinusoid() -> None:
    """z_s = z0 + a_x sin(2 pi x / l_x) + a_y sin(2 pi y / l_y) at quarter wavelengths."""
    t = terrain_sinusoid((0.02, 0.01), (1.0, 2.0), surface_z=-0.1)
    np.testing.assert_allclose(terrain_height(t, 0.25, 0.5), -0.1 + 0.02 + 0.01, atol=1e-15)


def test_grid_is_bilinear_and_clamped() -> None:
    """Nodes are exact, midpoints are averages, and the outside clamps to the border."""
    t = TerrainCfg(height="grid", grid=((0.0, 1.0), (2.0, 4.0)), grid_origin=(1.0, 1.0), grid_spacing=0.5)
    np.testing.assert_allclose(terrain_height(t, [1.0, 1.5, 1.0, 1.5], [1.0, 1.0, 1.5, 1.5]), [0, 1, 2, 4])
    np.testing.assert_allclose(terrain_height(t, 1.25, 1.25), (0 + 1 + 2 + 4) / 4)
    np.testing.assert_allclose(terrain_height(t, -5.0, 9.0), 2.0)


def test_tiled_levels() -> None:
    """Tile centres sit at their level."""
    levels = np.array([[0.0, -0.05], [-0.1, -0.12]])
    t = terrain_tiled_levels(levels, tile_size=8.0)
    np.testing.assert_allclose(terrain_height(t, [4.0, 12.0, 4.0, 12.0], [4.0, 4.0, 12.0, 12.0]), levels.ravel())


def test_material_transition() -> None:
    """Basalt -> dry sand -> poppy seed along x, blended linearly across each edge."""
    mats = tuple(MATERIAL_PRESETS[k] for k in ("basalt", "dry_sand", "poppy_seed"))
    t = terrain_transition(mats, (0.0, 5.0), blend=1.0)
    m = terrain_material(t, np.array([-3.0, 0.0, 2.0, 9.0]))
    np.testing.assert_allclose(m[0], [2700.0, mats[0].mu_int, 0.5])
    np.testing.assert_allclose(m[1, 0], 0.5 * (2700.0 + 1500.0))
    np.testing.assert_allclose(m[2], [1500.0, 0.6, 0.4])
    np.testing.assert_allclose(m[3], [638.0, 0.51, 0.3])
