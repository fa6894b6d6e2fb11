# SPDX-License-Identifier: Apache-2.0
"""Extension terms of 3D-RFT (RftExtensionsCfg): Warp kernels against the float64 reference, off == published model."""

from __future__ import annotations

import importlib.util
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import warp as wp

from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, g1_foot_box_cfg, make_contact_model
from gmloco.contact.config import AtRestMode, RftExtensionsCfg
from gmloco.contact.models import ContactRFT3D
from gmloco.contact.reference.rft3d_extensions import ExtState, advance_ext_state, rft3d_extended_forces

GOLDEN = Path(__file__).with_name("golden_data") / "rft3d_extensions_off"
SCRIPT = Path(__file__).parents[1] / "scripts" / "golden_rft3d_ext_off.py"


def _load_script():  # noqa: ANN202
    """Import the golden-data script by path (its trajectory and runner are the test's)."""
    spec = importlib.util.spec_from_file_location("golden_rft3d_ext_off", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


golden = _load_script()

TERMS: dict[str, RftExtensionsCfg] = {
    "depth_power": RftExtensionsCfg(depth_exponent=1.4, depth_ref=0.02),
    "depth_saturation": RftExtensionsCfg(depth_saturation=0.015),
    "lateral": RftExtensionsCfg(lateral_scale=0.05),
    "plastic_unloading": RftExtensionsCfg(plastic_unloading=True, footprint_radius=0.05),
    "overburden": RftExtensionsCfg(overburden=2.0),
    "added_mass": RftExtensionsCfg(added_mass=1.5),
    "loosening": RftExtensionsCfg(loosening_depth=0.01, loosening_length=0.02),
    "loosening_keep": RftExtensionsCfg(loosening_depth=0.03, loosening_length=0.02, loosening_keep=0.3),
    "erosion": RftExtensionsCfg(erosion_length=0.02, erosion_keep=0.2, erosion_restore=0.005),
    "rate_drag": RftExtensionsCfg(rate_drag=3.0),
    "bearing": RftExtensionsCfg(bearing=1.0),
    "all": RftExtensionsCfg(
        depth_exponent=0.8,
        depth_saturation=0.04,
        lateral_scale=0.3,
        plastic_unloading=True,
        footprint_radius=0.05,
        overburden=1.0,
        added_mass=0.7,
    ),
}
"""One configuration per candidate term (each on alone), and all together."""


@pytest.mark.parametrize("case", list(golden.CASES))
@pytest.mark.parametrize("fused", [True, False])
def test_extensions_off_equal_golden(device: str, case: str, fused: bool) -> None:
    """With every term off the wrenches and point forces equal those of the model without the terms, bit for bit.

    Golden data: ``scripts/golden_rft3d_ext_off.py`` run on the contact package of commit 446cd8e (no extension
    terms).
    """
    tag = f"{case}_{'fused' if fused else 'unfused'}"
    wrench, points = golden.run_model(golden.CASES[case], fused)
    np.testing.assert_array_equal(wrench.astype(np.float32), np.load(GOLDEN / f"{tag}_wrench.npy"))
    if not fused:
        np.testing.assert_array_equal(points.astype(np.float32), np.load(GOLDEN / f"{tag}_points.npy"))


def test_neutral_values_are_off(device: str) -> None:
    """Neutral term values with other depth_ref / tolerance / dt still give the published model bit for bit."""
    neutral = RftExtensionsCfg(depth_ref=0.3, unloading_tolerance=0.01, dt=0.002)
    assert neutral.is_off and not neutral.stateful
    base = golden.CASES["unloading"]
    a, _ = golden.run_model(base, True)
    b, _ = golden.run_model(replace(base, extensions=neutral), True)
    np.testing.assert_array_equal(a, b)


def _reference_run(cfg: ContactRFT3DCfg, model_points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the float64 reference (point forces [T, W, F, P, 3], mask of comparable elements) on the trajectory."""
    pos, rot, vel, ang, _ = golden.trajectory()
    col = make_contact_model(cfg, 1, 1, "cpu").collider
    mat = MATERIAL_PRESETS["dry_sand"]
    out = np.zeros_like(model_points, dtype=np.float64)
    ok = np.ones(model_points.shape[:-1], dtype=bool)
    for w in range(pos.shape[1]):
        for f in range(pos.shape[2]):
            state = ExtState.zeros(col.num_points)
            for t in range(pos.shape[0]):
                p32 = [np.asarray(a[t, w, f], dtype=np.float32).astype(np.float64) for a in (pos, rot, vel, ang)]
                r = col.points @ p32[1].T
                x, n, v = p32[0] + r, col.normals @ p32[1].T, p32[2] + np.cross(p32[3], r)
                out[t, w, f] = rft3d_extended_forces(x, n, v, col.areas, state, cfg, mat)
                depth = -x[:, 2]
                # clear of the branch boundaries that float32 rounding may flip (surface, z_max band, leading mask)
                ok[t, w, f] = (np.abs(depth) > 1e-5) & (np.abs(depth - state.depth_max) > 2e-4)
                state = advance_ext_state(state, x, n, v, cfg)
    return out, ok


@pytest.mark.parametrize("at_rest", ["none", "unloading"])
@pytest.mark.parametrize("term", list(TERMS))
def test_kernel_matches_reference(device: str, term: str, at_rest: AtRestMode) -> None:
    """Per-element forces of each term (fused step kernel) equal the float64 reference over press-lift-press-drag."""
    cfg = ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 3), at_rest=at_rest, extensions=TERMS[term])
    _, points = golden.run_model(cfg, True)
    # the fused kernel's point outputs equal the per-point path's (tests/test_fused.py); compare the per-point path
    _, points_unfused = golden.run_model(cfg, False)
    np.testing.assert_allclose(points, points_unfused, atol=1e-4 * max(1.0, np.abs(points).max()))
    ref, ok = _reference_run(cfg, points)
    scale = np.abs(ref).max()
    assert scale > 1.0
    np.testing.assert_allclose(points[ok], ref[ok], atol=2e-4 * scale)
    assert ok.mean() > 0.9


def test_each_term_changes_the_force(device: str) -> None:
    """Every term, on, changes the trajectory's wrenches (no term is silently inert)."""
    base = ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 3), at_rest="none")
    off, _ = golden.run_model(base, True)
    for name, ext in TERMS.items():
        on, _ = golden.run_model(replace(base, extensions=ext), True)
        assert np.abs(on - off).max() > 1e-3 * np.abs(off).max(), name


def _level_sole(depth: float, v: tuple[float, float, float]) -> tuple[np.ndarray, ...]:
    """Return a level foot [1, 1, ...] whose sole (z = -0.03539 in the body) is ``depth`` deep [m]."""
    return (
        np.array([[[0.0, 0.0, 0.03539 - depth]]]),
        np.eye(3)[None, None],
        np.array([[v]], dtype=np.float64),
        np.zeros((1, 1, 3)),
        np.zeros((1, 1, 3)),
    )


def _wrench(model, feet: tuple[np.ndarray, ...]) -> np.ndarray:  # noqa: ANN001
    """Return compute()'s wrench of one foot [6]."""
    types = (wp.vec3, wp.mat33, wp.vec3, wp.vec3, wp.vec3)
    arrays = [wp.array(a.astype(np.float32), dtype=t, device="cpu") for a, t in zip(feet, types, strict=True)]
    out = wp.zeros((1, 1), dtype=wp.spatial_vector, device="cpu")  # pyright: ignore[reportArgumentType]
    model.compute(*arrays, out)
    return out.numpy()[0, 0].astype(np.float64)


@pytest.mark.parametrize("term", list(TERMS))
def test_invariants_zero_above_and_monotone_in_depth(device: str, term: str) -> None:
    """Above the surface every term gives exactly 0; a pressed level sole's F_z > 0 grows strictly with depth."""
    model = make_contact_model(ContactRFT3DCfg(at_rest="none", extensions=TERMS[term]), 1, 1, device)
    assert np.all(_wrench(model, _level_sole(-0.001, (0.1, 0.0, 0.3))) == 0.0)
    assert np.all(_wrench(model, _level_sole(-0.001, (0.1, 0.0, -0.3))) == 0.0)
    f_z = [_wrench(model, _level_sole(d, (0.0, 0.0, -0.2)))[2] for d in np.linspace(0.002, 0.08, 12)]
    assert f_z[0] > 0.0 and np.all(np.diff(f_z) > 0.0)


def test_overburden_pulls_down_a_rising_sole(device: str) -> None:
    """A rising level sole at 20 mm gets F_z = -c_ob rho_c g d A (hand value below), 0 from plain RFT (trailing)."""
    # dry sand rho_c, A = 0.206 * 0.0736 = 0.0151616 m^2: F_z = -2 * rho_c * 9.81 * 0.02 * A
    model = make_contact_model(ContactRFT3DCfg(at_rest="none", extensions=TERMS["overburden"]), 1, 1, device)
    rho_c = MATERIAL_PRESETS["dry_sand"].rho_c
    expected = -2.0 * rho_c * 9.81 * 0.02 * 0.206 * 0.0736
    np.testing.assert_allclose(_wrench(model, _level_sole(0.02, (0.0, 0.0, 0.1)))[2], expected, rtol=1e-5)


def test_rate_drag_opposes_a_slide_in_proportion_to_speed(device: str) -> None:
    """A level sole 20 mm deep sliding at (0.5, 0.2) m/s gets -c_rd rho_c g d A v_xy on top of 3D-RFT (hand value)."""
    feet = _level_sole(0.02, (0.5, 0.2, -0.1))
    plain = _wrench(make_contact_model(ContactRFT3DCfg(at_rest="none"), 1, 1, device), feet)
    cfg = ContactRFT3DCfg(at_rest="none", extensions=TERMS["rate_drag"])
    dragged = _wrench(make_contact_model(cfg, 1, 1, device), feet)
    # only the sole face is submerged: A = 0.206 * 0.0736 m^2 at d = 0.02 m
    k = 3.0 * MATERIAL_PRESETS["dry_sand"].rho_c * 9.81 * 0.02 * 0.206 * 0.0736
    np.testing.assert_allclose(dragged[:3] - plain[:3], [-k * 0.5, -k * 0.2, 0.0], rtol=1e-4, atol=1e-3)
    assert k * 0.5 > 1.0


def test_bearing_keeps_a_sliding_sole_as_supported_as_a_pressed_one(device: str) -> None:
    """A level sole 20 mm deep sliding at 1 m/s keeps the F_z of a straight press.

    Its F_x, and a rising sole's whole force, are the published model's.
    """
    plain = make_contact_model(ContactRFT3DCfg(at_rest="none"), 1, 1, device)
    bearing = make_contact_model(ContactRFT3DCfg(at_rest="none", extensions=TERMS["bearing"]), 1, 1, device)
    slide, press, rise = (_level_sole(0.02, v) for v in ((1.0, 0.0, 0.0), (0.0, 0.0, -0.2), (1.0, 0.0, 0.05)))
    pressed_z = _wrench(plain, press)[2]
    slid_plain, slid = _wrench(plain, slide), _wrench(bearing, slide)
    assert slid_plain[2] < 0.5 * pressed_z  # 3D-RFT's support of a sliding sole falls
    np.testing.assert_allclose(slid[2], pressed_z, rtol=1e-5)
    np.testing.assert_allclose(slid[:2], slid_plain[:2], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(_wrench(bearing, rise), _wrench(plain, rise), rtol=1e-6, atol=1e-6)


def test_lateral_scale_scales_only_horizontal(device: str) -> None:
    """Dragging a sole: F_x, F_y are lateral_scale times the published model's, F_z unchanged (float32 tolerance)."""
    feet = _level_sole(0.02, (0.5, 0.2, -0.1))
    plain = _wrench(make_contact_model(ContactRFT3DCfg(at_rest="none"), 1, 1, device), feet)
    cfg = ContactRFT3DCfg(at_rest="none", extensions=TERMS["lateral"])
    scaled = _wrench(make_contact_model(cfg, 1, 1, device), feet)
    np.testing.assert_allclose(scaled[:3], plain[:3] * np.array([0.05, 0.05, 1.0]), rtol=1e-5, atol=1e-6)
    assert abs(plain[0]) > 1.0


def test_footprint_memory_and_plastic_unloading(device: str) -> None:
    """Stepping back into a 20 mm footprint: no force above its bottom, RFT again below it; forgotten elsewhere."""
    cfg = ContactRFT3DCfg(at_rest="none", extensions=TERMS["plastic_unloading"])
    model = make_contact_model(cfg, 1, 1, device)
    types = (wp.vec3, wp.mat33, wp.vec3, wp.vec3, wp.vec3)

    def step(feet: tuple[np.ndarray, ...]) -> None:
        model.update_state(*[wp.array(a.astype(np.float32), dtype=t) for a, t in zip(feet, types, strict=True)])

    step(_level_sole(0.02, (0.0, 0.0, -0.2)))  # footprint 20 mm deep
    step(_level_sole(-0.01, (0.0, 0.0, 0.2)))  # lifted out of the sand
    assert np.all(_wrench(model, _level_sole(0.015, (0.0, 0.0, -0.2))) == 0.0)  # inside the footprint
    assert _wrench(model, _level_sole(0.025, (0.0, 0.0, -0.2)))[2] > 0.0  # below its bottom
    moved = _level_sole(-0.01, (0.0, 0.0, 0.2))
    moved[0][..., 0] = 0.3  # swing 30 cm away: the footprint is forgotten
    step(moved)
    fresh = _level_sole(0.015, (0.0, 0.0, -0.2))
    fresh[0][..., 0] = 0.3
    assert _wrench(model, fresh)[2] > 0.0


def test_set_extensions_validates_and_randomizes(device: str) -> None:
    """Per-world values change only their world's force; unknown names and out-of-range values are refused."""
    cfg = ContactRFT3DCfg(at_rest="none", extensions=RftExtensionsCfg(lateral_scale=0.5))
    model = make_contact_model(cfg, 2, 1, device)
    assert isinstance(model, ContactRFT3D)
    model.set_extensions(env_ids=[1], lateral_scale=0.1)
    np.testing.assert_allclose(model.ext_values.numpy()[:, 3], [0.5, 0.1])
    with pytest.raises(ValueError, match="unknown"):
        model.set_extensions(bogus=1.0)
    with pytest.raises(ValueError, match="lateral_scale"):
        model.set_extensions(lateral_scale=-1.0)
    with pytest.raises(ValueError, match="depth_exponent"):
        RftExtensionsCfg(depth_exponent=0.0)
