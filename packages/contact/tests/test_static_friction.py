# SPDX-License-Identifier: Apache-2.0
"""Static friction in the crater (3D-RFT elastic branch): a Cundall-Strack stick spring with a Coulomb slider.

Hand-computed values for a level G1 sole at rest (v = 0) in its crater on dry sand (mu_surf = 0.4): every sole
element has n = (0, 0, -1), its static resistance is vertical, and its spring force is mu |F_n| s / s0 for a
sideways offset s from its anchor (s0 = 2 mm), capped at mu |F_n|. Summed over the sole: F_x = -mu F_z s / s0.
"""

from __future__ import annotations

import numpy as np
import pytest
import warp as wp

from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, g1_foot_box_cfg, make_contact_model

MU = MATERIAL_PRESETS["dry_sand"].mu_surf
SOLE_Z = -0.03539
"""Sole height in the ankle_roll_link frame [m] (spec 4)."""


def level_sole(depth: float, x: float, v: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> tuple[wp.array, ...]:
    """Return the Warp inputs [1, 1] of a level foot whose sole is ``depth`` deep, shifted by ``x`` along x [m]."""
    arrays = (
        np.array([[[x, 0.0, -SOLE_Z - depth]]]),
        np.eye(3)[None, None],
        np.array([[v]]),
        np.zeros((1, 1, 3)),
        np.array([[[x, 0.0, -SOLE_Z - depth]]]),
    )
    types = (wp.vec3, wp.mat33, wp.vec3, wp.vec3, wp.vec3)
    return tuple(wp.array(a.astype(np.float32), dtype=t, device="cpu") for a, t in zip(arrays, types, strict=True))


def force_at(model, depth: float, x: float) -> np.ndarray:  # noqa: ANN001
    """Return the foot's total force [N] at rest at (depth, x), without advancing the state."""
    out = wp.zeros((1, 1), dtype=wp.spatial_vector, device="cpu")
    model.compute(*level_sole(depth, x), out)
    return out.numpy()[0, 0, :3].astype(np.float64)


def pressed_model(static_friction: bool):  # noqa: ANN201
    """Return a sole model whose elements remember a 10 mm deep crater entered straight down at x = 0."""
    cfg = ContactRFT3DCfg(collider=g1_foot_box_cfg("sole", 4), static_friction=static_friction)
    model = make_contact_model(cfg, 1, 1, "cpu")
    model.update_state(*level_sole(0.010, 0.0, (0.0, 0.0, -0.1)))
    return model


@pytest.mark.parametrize("shift", [0.0005, 0.001, 0.0015])
def test_stick_spring_holds_a_static_sideways_load(device: str, shift: float) -> None:
    """At v = 0, a sole shifted by s < s0 in its crater resists with F_x = -mu F_z s / s0 (viscous law: 0)."""
    force = force_at(pressed_model(True), 0.0099, shift)
    assert force[2] > 10.0
    np.testing.assert_allclose(force[0], -MU * force[2] * shift / 0.002, rtol=1e-4)
    assert abs(force[1]) < 1e-6 * force[2]
    viscous = force_at(pressed_model(False), 0.0099, shift)
    assert viscous[0] == 0.0  # the previous law holds no static load: the foot creeps
    np.testing.assert_allclose(viscous[2], force[2], rtol=1e-6)  # the normal force is unchanged


def test_coulomb_slider_caps_and_keeps_the_slip(device: str) -> None:
    """Past s0 the force stays at mu F_z and the anchor slides; moving back reverses it (hysteresis).

    Shift 3 mm: F_x = -mu F_z (cap); update_state moves the anchor to x - s0 = 1 mm. Back at 2 mm: offset 1 mm,
    F_x = -mu F_z / 2. Back at 0: offset -1 mm, F_x = +mu F_z / 2.
    """
    model = pressed_model(True)
    depth = 0.0099
    capped = force_at(model, depth, 0.003)
    np.testing.assert_allclose(capped[0], -MU * capped[2], rtol=1e-5)
    model.update_state(*level_sole(depth, 0.003))
    np.testing.assert_allclose(model.anchor.numpy()[0, 0, :, 0] - model.collider.points[:, 0], 0.001, atol=1e-6)
    for x, ratio in ((0.002, -0.5), (0.0, 0.5)):
        force = force_at(model, depth, x)
        np.testing.assert_allclose(force[0], ratio * MU * force[2], rtol=1e-3)


def test_loading_resets_the_anchor(device: str) -> None:
    """An element pushed deeper than its crater (plastic loading) re-anchors at its position: no stored offset."""
    model = pressed_model(True)
    model.update_state(*level_sole(0.012, 0.004, (0.1, 0.0, -0.1)))  # deeper and sliding: loading branch
    np.testing.assert_allclose(model.anchor.numpy()[0, 0, :, 0] - model.collider.points[:, 0], 0.004, atol=1e-6)
    force = force_at(model, 0.0119, 0.004)
    assert abs(force[0]) < 1e-6 * force[2]


def test_static_friction_off_in_other_modes(device: str) -> None:
    """Only 3D-RFT with at_rest="unloading" and static_friction=True keeps anchors (stick distance > 0)."""
    assert pressed_model(True).rest.stick_distance == 0.002
    assert pressed_model(False).rest.stick_distance == 0.0
    for mode in ("none", "ema"):
        model = make_contact_model(ContactRFT3DCfg(at_rest=mode), 1, 1, "cpu")
        assert model.rest.stick_distance == 0.0


def test_stateful_sequence_matches_float64_reference(device: str) -> None:
    """Kernel forces and anchors over a sliding, pressing and lifting sequence = the float64 reference's own state.

    The reference keeps its own z_max and anchors (``advance_stick_anchors``, z_max = max(z_max, d) in contact,
    0 out of it) from the float32-rounded inputs, so the whole stateful chain is compared, not one step. Impact
    damping is off (its gate needs the EMA reversal counter, which the reference does not model). Elements within
    1 um of a branch boundary (d = 0, d = z_max, |s_t| = s0) are skipped: float32 may take the other branch.
    """
    from gmloco.contact.reference import advance_stick_anchors, rft3d_unloading_forces

    rng = np.random.default_rng(4)
    n_feet, mat = 4, MATERIAL_PRESETS["dry_sand"]
    cfg = ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 3), unloading_speed=0.0)
    model = make_contact_model(cfg, 1, n_feet, "cpu")
    col = model.collider
    rot = np.stack([np.eye(3)] * n_feet) @ np.linalg.qr(np.eye(3) + 0.05 * rng.normal(size=(n_feet, 3, 3)))[0]
    rot *= np.sign(np.linalg.det(rot))[:, None, None]  # proper rotations, tilted a few degrees
    pos = np.column_stack([rng.uniform(-0.3, 0.3, (n_feet, 2)), np.full(n_feet, 0.03539 - 0.012)])
    depth_max = np.zeros((n_feet, col.num_points))
    anchors = np.zeros((n_feet, col.num_points, 3))
    checked = {"elastic": 0, "slipping": 0}
    for step in range(14):
        pos = pos + np.column_stack([rng.uniform(-1.5e-3, 1.5e-3, (n_feet, 2)), rng.uniform(-1e-3, 1e-3, n_feet)])
        vel = rng.normal(scale=0.05, size=(n_feet, 3))
        arrays = (pos, rot, vel, np.zeros((n_feet, 3)), pos)
        inputs = tuple(
            wp.array(a[None].astype(np.float32), dtype=t, device="cpu")
            for a, t in zip(arrays, (wp.vec3, wp.mat33, wp.vec3, wp.vec3, wp.vec3), strict=True)
        )
        out = wp.zeros((1, n_feet), dtype=wp.spatial_vectorf, device="cpu")
        model.compute(*inputs, out)
        forces = model.point_force.numpy()[0].astype(np.float64)
        model.update_state(*inputs)
        for f in range(n_feet):
            p32, r32, v32 = (np.asarray(a[f], dtype=np.float32).astype(np.float64) for a in (pos, rot, vel))
            x, n, v = p32 + col.points @ r32.T, col.normals @ r32.T, np.tile(v32, (col.num_points, 1))
            depth = -x[:, 2]
            ref = rft3d_unloading_forces(
                x, n, v, col.areas, depth_max[f], rho_c=mat.rho_c, mu_int=mat.mu_int, mu_surf=mat.mu_surf,
                ratio=cfg.unloading_ratio, tangential_damping=cfg.tangential_damping, damping=cfg.unloading_damping,
                anchors=anchors[f], stick_distance=cfg.stick_distance,
            )  # fmt: skip
            s_t = (x - anchors[f]) - np.sum((x - anchors[f]) * n, -1, keepdims=True) * n
            slip = np.linalg.norm(s_t, axis=-1)
            ok = (np.abs(depth) > 1e-6) & (np.abs(depth - depth_max[f]) > 1e-6) & (np.abs(slip - 0.002) > 1e-6)
            scale = max(np.abs(ref).max(), 1e-9)
            np.testing.assert_allclose(forces[f][ok], ref[ok], atol=1e-4 * scale, err_msg=f"step {step} foot {f}")
            elastic = ok & (depth > 0.0) & (depth < depth_max[f])
            checked["elastic"] += int(elastic.sum())
            checked["slipping"] += int((elastic & (slip > 0.002)).sum())
            new_anchors = advance_stick_anchors(x, n, anchors[f], depth_max[f], cfg.stick_distance)
            anchors[f] = np.where((depth > 0.0)[:, None], new_anchors, anchors[f])
            depth_max[f] = np.where(depth > 0.0, np.maximum(depth_max[f], depth), 0.0)
            sub = depth > 0.0
            np.testing.assert_allclose(model.anchor.numpy()[0, f][sub], anchors[f][sub], atol=2e-6)
            np.testing.assert_allclose(model.depth_max.numpy()[0, f], depth_max[f], atol=1e-7)
    assert checked["elastic"] > 50 and checked["slipping"] > 10, checked  # both crater regimes were exercised
