# SPDX-License-Identifier: Apache-2.0
"""Colliders: cell-centred points, exact areas, outward normals, the G1 foot of spec 4."""

from __future__ import annotations

import numpy as np
import pytest

from gmloco.contact import ColliderBoxCfg, box_collider, g1_foot_collider


def test_g1_sole_geometry() -> None:
    """5 x 5 sole: 25 points at z = -0.03539, normals -z, areas summing to 0.206 x 0.0736 m^2."""
    sole = g1_foot_collider("sole", 5)
    assert sole.num_points == 25
    np.testing.assert_allclose(sole.points[:, 2], -0.03539)
    np.testing.assert_allclose(sole.normals, np.tile([0, 0, -1.0], (25, 1)))
    np.testing.assert_allclose(sole.areas.sum(), 0.206 * 0.0736, rtol=1e-12)
    # cell centres: first x centre = -0.065 + 0.206 / 10
    np.testing.assert_allclose(sole.points[:, 0].min(), -0.065 + 0.0206, rtol=1e-12)


@pytest.mark.parametrize("resolution", [1, 3, 7, (4, 2, 3)])
def test_box_faces_are_exact(resolution: int | tuple[int, int, int]) -> None:
    """Six faces: total area = 2(lx ly + ly lz + lx lz); normals outward; centroid of the surface = box centre."""
    cfg = ColliderBoxCfg((-0.1, 0.3), (-0.05, 0.15), (-0.2, 0.0), "box", resolution)
    box = box_collider(cfg)
    lx, ly, lz = 0.4, 0.2, 0.2
    np.testing.assert_allclose(box.areas.sum(), 2 * (lx * ly + ly * lz + lx * lz), rtol=1e-12)
    centre = np.array([0.1, 0.05, -0.1])
    assert np.all(np.sum((box.points - centre) * box.normals, 1) > 0.0)  # outward
    np.testing.assert_allclose((box.points * box.areas[:, None]).sum(0) / box.areas.sum(), centre, atol=1e-12)
    # area-weighted normals of a closed surface sum to zero
    np.testing.assert_allclose((box.normals * box.areas[:, None]).sum(0), 0.0, atol=1e-15)


def test_invalid_box_is_rejected() -> None:
    """Empty extents, zero resolution and an unknown face set fail at construction."""
    with pytest.raises(ValueError, match="x_range"):
        ColliderBoxCfg(x_range=(0.1, 0.1))
    with pytest.raises(ValueError, match="resolution"):
        ColliderBoxCfg(resolution=0)
    with pytest.raises(ValueError, match=r"'sole'.*'box'"):
        ColliderBoxCfg(faces="boxes")  # type: ignore[arg-type]
