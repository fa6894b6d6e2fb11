# SPDX-License-Identifier: Apache-2.0
"""Term (g) of RftExtensionsCfg, support erosion by horizontal travel, on the float64 reference.

The kernels' parity with the reference is in test_rft3d_extensions.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, RftExtensionsCfg
from gmloco.contact.reference.rft3d_extensions import (
    ExtState,
    advance_erosion,
    advance_ext_state,
    erosion_factor,
    rft3d_extended_forces,
)

ERODE = RftExtensionsCfg(erosion_length=0.01, erosion_keep=0.2, erosion_restore=0.003, dt=0.01)


def _sole() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A flat 10 x 4 cm plate of 4 x 4 downward-facing elements at the origin (points, normals, areas)."""
    xs, ys = np.meshgrid(np.linspace(-0.04, 0.04, 4), np.linspace(-0.015, 0.015, 4))
    pts = np.stack([xs.ravel(), ys.ravel(), np.zeros(16)], 1)
    return pts, np.tile([0.0, 0.0, -1.0], (16, 1)), np.full(16, 0.1 * 0.04 / 16)


def _slide_and_repress(ext: RftExtensionsCfg, slide_m: float, repress_m: float) -> list[float]:
    """Press a plate 2 cm, rest, slide ``slide_m`` at constant depth, rest, press ``repress_m`` further, rest.

    Returns F_z [N] at the end of each rest: [loaded, after the slide, after the re-press].
    """
    cfg = ContactRFT3DCfg(at_rest="unloading", extensions=ext)
    pts, normals, areas = _sole()
    mat = MATERIAL_PRESETS["dry_sand"]
    state = ExtState.zeros(16)
    down, side, rest = np.array([0.0, 0.0, -0.05]), np.array([0.1, 0.0, 0.0]), np.zeros(3)
    steps = lambda metres, speed: round(metres / speed / ext.dt)  # noqa: E731
    phases = [(down, steps(0.02, 0.05)), (rest, 5), (side, steps(slide_m, 0.1)), (rest, 5)]
    phases += [(down, steps(repress_m, 0.05)), (rest, 5)]
    z, x, fz, out = 0.0, 0.0, 0.0, []
    for vel, n in phases:
        for _ in range(n):
            p = pts + np.array([x, 0.0, -z])
            v = np.tile(vel, (16, 1))
            fz = float(rft3d_extended_forces(p, normals, v, areas, state, cfg, mat)[:, 2].sum())
            state = advance_ext_state(state, p, normals, v, cfg)
            z, x = z - vel[2] * ext.dt, x + vel[0] * ext.dt
        if not vel.any():
            out.append(fz)
    return out


def test_off_by_default_and_neutral() -> None:
    """erosion_length 0 is the published model (is_off, not stateful) whatever its keep and restore length."""
    assert RftExtensionsCfg(erosion_keep=0.7, erosion_restore=0.02).is_off
    assert not RftExtensionsCfg(erosion_keep=0.7).stateful and ERODE.stateful
    loaded, slid, _ = _slide_and_repress(RftExtensionsCfg(dt=0.01), 0.1, 0.005)
    assert loaded > 0.0 and slid == pytest.approx(loaded, rel=1e-9)


def test_a_slide_erodes_support_down_to_the_keep_share() -> None:
    """After a slide the support at rest falls, more after a longer one, and never below the keep share."""
    loaded, short, _ = _slide_and_repress(ERODE, 0.01, 0.005)
    _, long, _ = _slide_and_repress(ERODE, 0.10, 0.005)
    assert ERODE.erosion_keep * loaded <= long < short < loaded
    assert long == pytest.approx(ERODE.erosion_keep * loaded, rel=0.02)  # 10 slide lengths: fully eroded


def test_a_repress_restores_the_support_within_a_few_restore_lengths() -> None:
    """Pressing 1 cm (> 3 restore lengths) past z_max after a slide carries at least the load before it again."""
    loaded, slid, repressed = _slide_and_repress(ERODE, 0.10, 0.01)
    assert slid < 0.3 * loaded and repressed > loaded


def test_share_follows_its_law() -> None:
    """Grows by (1 - s) |v_xy| dt / L_e, shrinks by exp(-dz / restore) past z_max, 0 out of the sand."""
    v = np.array([[0.1, 0.0, 0.0], [0.0, 0.0, -0.05], [0.1, 0.0, 0.0]])
    share = np.array([0.5, 0.5, 0.5])
    depth, depth_max = np.array([0.02, 0.023, -0.001]), np.array([0.02, 0.02, 0.02])
    got = advance_erosion(share, v, depth, depth_max, ERODE)
    np.testing.assert_allclose(got, [0.5 + 0.5 * 0.1, 0.5 * np.exp(-1.0), 0.0], rtol=1e-12)
    np.testing.assert_allclose(erosion_factor(np.array([0.0, 1.0]), ERODE), [1.0, 0.2], rtol=1e-12)
    np.testing.assert_array_equal(erosion_factor(np.array([0.4]), RftExtensionsCfg()), 1.0)


def test_bad_values_are_refused() -> None:
    """A negative length, a keep outside [0, 1), a non-positive restore length, or erosion with loosening."""
    for bad in ({"erosion_length": -0.01}, {"erosion_keep": 1.0}, {"erosion_restore": 0.0}):
        with pytest.raises(ValueError, match="erosion"):
            RftExtensionsCfg(**bad)
    with pytest.raises(ValueError, match="one travel memory"):
        RftExtensionsCfg(erosion_length=0.01, loosening_depth=0.01)
