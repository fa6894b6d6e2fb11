# SPDX-License-Identifier: Apache-2.0
"""Terms (f) loosening and (g) support erosion of RftExtensionsCfg (horizontal travel), on the float64 reference.

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
    loosening_shift,
    rft3d_extended_forces,
)

LOOSE = RftExtensionsCfg(loosening_depth=0.01, loosening_length=0.05, dt=0.01)
ERODE = RftExtensionsCfg(erosion_length=0.01, erosion_keep=0.2, erosion_restore=0.003, dt=0.01)
DOWN, SIDE, REST = np.array([0.0, 0.0, -0.05]), np.array([0.1, 0.0, 0.0]), np.zeros(3)
"""Plate velocities [m/s]: pressing, sliding along x, at rest."""


def _sole() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A flat 10 x 4 cm plate of 4 x 4 downward-facing elements at the origin (points, normals, areas)."""
    xs, ys = np.meshgrid(np.linspace(-0.04, 0.04, 4), np.linspace(-0.015, 0.015, 4))
    pts = np.stack([xs.ravel(), ys.ravel(), np.zeros(16)], 1)
    return pts, np.tile([0.0, 0.0, -1.0], (16, 1)), np.full(16, 0.1 * 0.04 / 16)


def _drive_plate(ext: RftExtensionsCfg, phases: list[tuple[np.ndarray, float]]) -> list[float]:
    """Move a plate on dry sand through (velocity, metres) phases, rests 5 steps each; return F_z [N] after each rest.

    Starts with its sole at the surface; a rest phase's metres are ignored.
    """
    cfg = ContactRFT3DCfg(at_rest="unloading", extensions=ext)
    pts, normals, areas = _sole()
    mat = MATERIAL_PRESETS["dry_sand"]
    state = ExtState.zeros(16)
    z, x, fz, out = 0.0, 0.0, 0.0, []
    for vel, metres in phases:
        steps = 5 if not vel.any() else round(metres / float(np.linalg.norm(vel)) / ext.dt)
        for _ in range(steps):
            p = pts + np.array([x, 0.0, -z])
            v = np.tile(vel, (16, 1))
            fz = float(rft3d_extended_forces(p, normals, v, areas, state, cfg, mat)[:, 2].sum())
            state = advance_ext_state(state, p, normals, v, cfg)
            z, x = z - vel[2] * ext.dt, x + vel[0] * ext.dt
        if not vel.any():
            out.append(fz)
    return out


def _support_after_slide(ext: RftExtensionsCfg, slide_m: float, depth: float = 0.02) -> tuple[float, float]:
    """Press a plate to ``depth``, slide it ``slide_m`` at constant depth, stop; return (F_z before, F_z at rest after)."""
    before, after = _drive_plate(ext, [(DOWN, depth), (REST, 0.0), (SIDE, slide_m), (REST, 0.0)])
    return before, after


def _slide_and_repress(ext: RftExtensionsCfg, slide_m: float, repress_m: float) -> list[float]:
    """Press 2 cm, slide ``slide_m``, press ``repress_m`` further; F_z at rest after each: [loaded, slid, re-pressed]."""
    phases = [(DOWN, 0.02), (REST, 0.0), (SIDE, slide_m), (REST, 0.0), (DOWN, repress_m), (REST, 0.0)]
    return _drive_plate(ext, phases)


# (f) loosening


def test_loosening_off_by_default_and_neutral() -> None:
    """loosening_depth 0 is the published model (is_off, not stateful); the plate keeps its support after a slide."""
    assert RftExtensionsCfg(loosening_length=0.2).is_off and not RftExtensionsCfg().stateful
    before, after = _support_after_slide(RftExtensionsCfg(dt=0.01), 0.1)
    assert before > 0.0 and after == pytest.approx(before, rel=1e-9)


def test_a_slide_costs_support_that_grows_with_travel() -> None:
    """With loosening the support at rest after a slide falls below the support before, more after a longer slide."""
    before, after_short = _support_after_slide(LOOSE, 0.02)
    _, after_long = _support_after_slide(LOOSE, 0.10)
    assert 0.0 < after_long < after_short < before


def test_keep_bounds_the_support_lost() -> None:
    """With a keep share the slid plate keeps at least that share of its support; keep 0 is the shift alone."""
    deep = RftExtensionsCfg(loosening_depth=0.05, loosening_length=0.02, dt=0.01)
    before, after = _support_after_slide(deep, 0.10)
    assert after == 0.0  # a 5 cm shift empties a 2 cm press
    keep = RftExtensionsCfg(loosening_depth=0.05, loosening_length=0.02, loosening_keep=0.25, dt=0.01)
    _, kept = _support_after_slide(keep, 0.10)
    assert 0.2 * before < kept < 0.35 * before  # ~ keep of the depth, at rest on the elastic branch
    assert not RftExtensionsCfg(loosening_keep=0.5).stateful  # keep alone is off (no shift to bound)
    assert RftExtensionsCfg(loosening_keep=0.5).is_off


def test_loosening_shift_follows_its_law() -> None:
    """Shift = d_l (1 - exp(-u / L)): 0 at no travel, d_l (1 - 1/e) at u = L, below d_l always."""
    u = np.array([0.0, 0.05, 10.0])
    np.testing.assert_allclose(loosening_shift(u, LOOSE), [0.0, 0.01 * (1 - np.exp(-1.0)), 0.01], rtol=1e-12)
    np.testing.assert_array_equal(loosening_shift(u, RftExtensionsCfg()), 0.0)


def test_loosening_bad_values_are_refused() -> None:
    """A negative depth, a non-positive length or a keep share outside [0, 1) is refused, naming the field."""
    for bad in ({"loosening_depth": -0.01}, {"loosening_length": 0.0}, {"loosening_keep": 1.0}):
        with pytest.raises(ValueError, match="loosening"):
            RftExtensionsCfg(**bad)


# (g) support erosion


def test_erosion_off_by_default_and_neutral() -> None:
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


def test_erosion_share_follows_its_law() -> None:
    """Grows by (1 - s) |v_xy| dt / L_e, shrinks by exp(-dz / restore) past z_max, 0 out of the sand."""
    v = np.array([[0.1, 0.0, 0.0], [0.0, 0.0, -0.05], [0.1, 0.0, 0.0]])
    share = np.array([0.5, 0.5, 0.5])
    depth, depth_max = np.array([0.02, 0.023, -0.001]), np.array([0.02, 0.02, 0.02])
    got = advance_erosion(share, v, depth, depth_max, ERODE)
    np.testing.assert_allclose(got, [0.5 + 0.5 * 0.1, 0.5 * np.exp(-1.0), 0.0], rtol=1e-12)
    np.testing.assert_allclose(erosion_factor(np.array([0.0, 1.0]), ERODE), [1.0, 0.2], rtol=1e-12)
    np.testing.assert_array_equal(erosion_factor(np.array([0.4]), RftExtensionsCfg()), 1.0)


def test_erosion_bad_values_are_refused() -> None:
    """A negative length, a keep outside [0, 1), a non-positive restore length, or erosion with loosening."""
    for bad in ({"erosion_length": -0.01}, {"erosion_keep": 1.0}, {"erosion_restore": 0.0}):
        with pytest.raises(ValueError, match="erosion"):
            RftExtensionsCfg(**bad)
    with pytest.raises(ValueError, match="one travel memory"):
        RftExtensionsCfg(erosion_length=0.01, loosening_depth=0.01)
