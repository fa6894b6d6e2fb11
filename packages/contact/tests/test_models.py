# SPDX-License-Identifier: Apache-2.0
"""Warp kernels (CPU device) against the float64 reference; API contract; state semantics; bad input.

Tolerances: the kernels run in float32 (eps = 6e-8). Forces are sums of ~20 O(1) cubic terms times xi depth dS,
so their absolute error is bounded by ~1e-5 of the force scale xi d dS; we compare with atol = 1e-4 * max|F|
and skip elements within 1e-3 of a mask boundary (n.v_hat = 0, depth = 0) where float32 may flip the mask.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest
import warp as wp

from gmloco.contact import (
    MATERIAL_PRESETS,
    ContactConeMultiCfg,
    ContactConeSingleCfg,
    ContactHeuristicRFTCfg,
    ContactRFT3DCfg,
    ContactRigidCfg,
    eta,
    g1_foot_box_cfg,
    make_contact_model,
    terrain_sinusoid,
    terrain_transition,
)
from gmloco.contact.reference import (
    ConeParams,
    ConeState,
    advance_stick_anchors,
    cone_step,
    foot_wrench,
    heuristic_rft_forces,
    rft3d_forces,
    rft3d_unloading_forces,
)
from gmloco.contact.terrain import terrain_height, terrain_material

W, F = 6, 2


def _load_helpers():  # noqa: ANN202
    """Import tests/helpers.py by path (pytest uses --import-mode=importlib)."""
    spec = importlib.util.spec_from_file_location("contact_test_helpers", Path(__file__).with_name("helpers.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_helpers = _load_helpers()
element_kinematics, foot_arrays, random_rotations = (
    _helpers.element_kinematics,
    _helpers.foot_arrays,
    _helpers.random_rotations,
)


def random_feet(seed: int, depth: float = 0.02, tilt: float = 0.4, speed: float = 0.5) -> tuple[np.ndarray, ...]:
    """Return (pos, rot, lin_vel, ang_vel, com) [W, F, ...] for feet around the surface."""
    rng = np.random.default_rng(seed)
    pos = rng.uniform([-0.5, -0.5, -depth], [0.5, 0.5, depth], (W, F, 3))
    rot = random_rotations(rng, W * F, tilt).reshape(W, F, 3, 3)
    vel = rng.normal(scale=speed, size=(W, F, 3))
    ang = rng.normal(scale=2.0, size=(W, F, 3))
    com = pos + rng.normal(scale=0.02, size=(W, F, 3))
    return pos, rot, vel, ang, com


def run(model, feet: tuple[np.ndarray, ...]) -> np.ndarray:  # noqa: ANN001
    """Run compute() and return the wrenches [W, F, 6]."""
    out = wp.zeros((W, F), dtype=wp.spatial_vector, device="cpu")
    model.compute(*foot_arrays(*feet), out)
    return out.numpy().copy()


def set_random_materials(model, seed: int) -> np.ndarray:  # noqa: ANN001
    """Give every world a random material from the paper's DR box; return [W, 3] (rho_c, mu_int, mu_surf)."""
    rng = np.random.default_rng(seed)
    mats = np.column_stack([rng.uniform(500, 3000, W), rng.uniform(0.1, 1.0, W), rng.uniform(0.1, 1.0, W)])
    model.set_materials(mats[:, 0], mats[:, 1], mats[:, 2])
    return mats


def well_conditioned(normals: np.ndarray, vel: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """Mask of elements clear of the leading-mask and surface boundaries."""
    v_hat = vel / np.linalg.norm(vel, axis=1, keepdims=True)
    return (np.abs(np.sum(normals * v_hat, 1)) > 1e-3) & (np.abs(depth) > 1e-3)


@pytest.mark.parametrize("faces", ["sole", "box"])
@pytest.mark.parametrize("coeffs", ["pnas", "gmloco"])
def test_rft3d_kernel_matches_reference(device: str, faces: str, coeffs: str) -> None:
    """Per-element forces equal rft3d_forces on random poses, velocities and per-world materials."""
    cfg = ContactRFT3DCfg(collider=g1_foot_box_cfg(faces, 4), coeffs=coeffs, at_rest="none")
    model = make_contact_model(cfg, W, F, device)
    mats = set_random_materials(model, 7)
    feet = random_feet(11)
    run(model, feet)
    forces = model.point_force.numpy()
    col = model.collider
    checked = 0
    for w in range(W):
        for f in range(F):
            pts, nrm, vel = element_kinematics(col.points, col.normals, *(a[w, f] for a in feet[:4]))
            ref = rft3d_forces(
                pts, nrm, vel, col.areas, rho_c=mats[w, 0], mu_int=mats[w, 1], mu_surf=mats[w, 2], coeffs=coeffs
            )
            ok = well_conditioned(nrm, vel, -pts[:, 2])
            scale = max(np.abs(ref).max(), 1e-9)
            np.testing.assert_allclose(forces[w, f][ok], ref[ok], atol=1e-4 * scale)
            checked += np.count_nonzero(np.abs(ref[ok]).sum(1) > 0.0)
    assert checked > 20  # enough loaded elements were compared


def test_wrench_is_torque_about_com(device: str) -> None:
    """Wrench = (sum F, sum (p_i - p_com) x F_i) and equals tau_ankle + (p_ankle - p_com) x F."""
    model = make_contact_model(ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 3), at_rest="none"), W, F, device)
    feet = random_feet(3)
    wrench = run(model, feet)
    forces = model.point_force.numpy().astype(np.float64)
    for w in range(W):
        for f in range(F):
            pos, rot, com = feet[0][w, f], feet[1][w, f], feet[4][w, f]
            pts = pos + model.collider.points @ rot.T
            force, tau_ankle = foot_wrench(pts, forces[w, f], pos)
            tau_com = tau_ankle + np.cross(pos - com, force)
            _, tau_direct = foot_wrench(pts, forces[w, f], com)
            np.testing.assert_allclose(tau_com, tau_direct, atol=1e-9 * max(1.0, np.abs(force).max()))
            scale = max(np.abs(force).max(), 1e-6)
            np.testing.assert_allclose(wrench[w, f, :3], force, atol=1e-5 * scale)
            np.testing.assert_allclose(wrench[w, f, 3:], tau_com, atol=1e-5 * scale)


def test_heuristic_kernel_matches_reference(device: str) -> None:
    """Heuristic-RFT element forces equal heuristic_rft_forces (F_z >= 0 clamp, Coulomb with k_f)."""
    model = make_contact_model(ContactHeuristicRFTCfg(collider=g1_foot_box_cfg("box", 3), at_rest="none"), W, F, device)
    mats = set_random_materials(model, 8)
    feet = random_feet(12)
    run(model, feet)
    forces = model.point_force.numpy()
    col = model.collider
    for w in range(W):
        for f in range(F):
            pts, nrm, vel = element_kinematics(col.points, col.normals, *(a[w, f] for a in feet[:4]))
            ref = heuristic_rft_forces(
                pts, nrm, vel, col.areas, rho_c=mats[w, 0], mu_int=mats[w, 1], mu_surf=mats[w, 2]
            )
            ok = np.abs(pts[:, 2]) > 1e-3
            np.testing.assert_allclose(forces[w, f][ok], ref[ok], atol=1e-4 * max(np.abs(ref).max(), 1e-9))


def test_unloading_branch_matches_reference(device: str) -> None:
    """After update_state stores z_max and the stick anchors, lifting and sliding a foot follows the reference.

    Substeps: press (z_max and anchors at touch-down), slide 1 mm or 4 mm sideways inside the crater (anchors
    follow beyond the 2 mm stick distance: advance_stick_anchors), then lift 2 mm while sliding
    (rft3d_unloading_forces: elastic branch with the stick spring).
    """
    cfg = ContactRFT3DCfg(collider=g1_foot_box_cfg("sole", 4), unloading_ratio=3.0, unloading_damping=0.002)
    model = make_contact_model(cfg, W, F, device)
    pos, rot, vel, ang, com = random_feet(5, tilt=0.1)
    pos[..., 2] = 0.02  # soles ~15 mm deep
    vel[..., 2] = -np.abs(vel[..., 2])
    col = model.collider
    model.update_state(*foot_arrays(pos, rot, vel, ang * 0, com))
    slide = np.zeros_like(pos)
    slide[..., 0] = np.where(np.arange(W)[:, None] % 2 == 0, 0.001, 0.004)  # inside / beyond the stick distance
    slid = pos + slide + np.array([0.0, 0.0, 0.0005])  # a little shallower: elastic branch
    anchors_before = model.anchor.numpy().astype(np.float64)
    depth_max = model.depth_max.numpy().astype(np.float64)
    model.update_state(*foot_arrays(slid, rot, vel, ang * 0, com))
    anchors = model.anchor.numpy().astype(np.float64)
    moved = np.linalg.norm(anchors - anchors_before, axis=-1).max(axis=-1)  # [W, F]
    assert moved[1::2].min() > 1e-3 and moved[::2].max() < 1e-6  # 4 mm slides the anchors, 1 mm does not
    lifted = slid + np.array([0.0, 0.0, 0.002]) + slide
    vel_up = vel.copy()
    vel_up[..., 2] = 0.05
    run(model, (lifted, rot, vel_up, ang * 0, com))
    forces = model.point_force.numpy()
    mat = MATERIAL_PRESETS["dry_sand"]
    for w in range(W):
        for f in range(F):
            pts, nrm, _ = element_kinematics(col.points, col.normals, pos[w, f], rot[w, f], vel[w, f], np.zeros(3))
            touch_down = advance_stick_anchors(pts, nrm, np.zeros_like(pts), np.zeros(len(pts)), cfg.stick_distance)
            np.testing.assert_allclose(anchors_before[w, f], touch_down, atol=2e-6)
            pts, nrm, _ = element_kinematics(col.points, col.normals, slid[w, f], rot[w, f], vel[w, f], np.zeros(3))
            ref_anchor = advance_stick_anchors(pts, nrm, anchors_before[w, f], depth_max[w, f], cfg.stick_distance)
            np.testing.assert_allclose(anchors[w, f], ref_anchor, atol=2e-6)
            pts, nrm, v = element_kinematics(
                col.points, col.normals, lifted[w, f], rot[w, f], vel_up[w, f], np.zeros(3)
            )
            ref = rft3d_unloading_forces(
                pts,
                nrm,
                v,
                col.areas,
                model.depth_max.numpy()[w, f].astype(np.float64),
                rho_c=mat.rho_c,
                mu_int=mat.mu_int,
                mu_surf=mat.mu_surf,
                ratio=3.0,
                tangential_damping=cfg.tangential_damping,
                damping=0.002,
                unloading_speed=cfg.unloading_speed,
                anchors=anchors[w, f],
                stick_distance=cfg.stick_distance,
            )
            assert np.abs(ref).max() > 0.0
            np.testing.assert_allclose(forces[w, f], ref, atol=1e-4 * np.abs(ref).max())


def test_monotone_loading_is_unchanged_by_at_rest_modes(device: str) -> None:
    """While every element goes deeper than before (walking-speed intrusion) all modes give plain 3D-RFT."""
    feet = random_feet(9, tilt=0.2)
    feet[2][..., 2] = -0.5  # pressing down at 0.5 m/s
    results = []
    for mode in ("none", "unloading"):
        model = make_contact_model(ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 3), at_rest=mode), W, F, device)
        shallower = (feet[0] + np.array([0, 0, 0.005]), *feet[1:])
        model.update_state(*foot_arrays(*shallower))  # memory of a shallower pose
        results.append(run(model, feet))
    np.testing.assert_array_equal(results[0], results[1])


def level_foot(depth: float, v_z: float) -> tuple[np.ndarray, ...]:
    """Return a level G1 foot [1, 1, ...] whose sole (z = -0.03539 in the body) is ``depth`` deep [m]."""
    return (
        np.array([[[0.0, 0.0, 0.03539 - depth]]]),
        np.eye(3)[None, None],
        np.array([[[0.0, 0.0, v_z]]]),
        np.zeros((1, 1, 3)),
        np.zeros((1, 1, 3)),
    )


def test_cone_kernels_match_reference(device: str) -> None:
    """Cone single and multi vertical forces equal cone_step for level soles (plastic and elastic cases)."""
    for cfg_type, multi in ((ContactConeSingleCfg, False), (ContactConeMultiCfg, True)):
        model = make_contact_model(
            cfg_type(unloading_ratio=5.0, unloading_damping=0.0, unloading_speed=0.0), 1, 1, device
        )
        r_h = model.radii.numpy()[0]
        p = ConeParams(r_h=float(r_h), mu=0.4, unloading_ratio=5.0)
        out = wp.zeros((1, 1), dtype=wp.spatial_vector, device=device)
        model.compute(*foot_arrays(*level_foot(0.02, -0.3)), out)  # penetrating at 0.3 m/s
        f_ref, state = cone_step(0.02, 0.3, np.zeros(2), ConeState(), p)
        n = model.num_points
        np.testing.assert_allclose(out.numpy()[0, 0, 2], n * f_ref[2], rtol=1e-5)
        model.update_state(*foot_arrays(*level_foot(0.02, -0.3)))
        model.compute(*foot_arrays(*level_foot(0.019, 0.1)), out)  # withdrawing 1 mm: elastic line
        f_ref, _ = cone_step(0.019, -0.1, np.zeros(2), state, p)
        np.testing.assert_allclose(out.numpy()[0, 0, 2], n * f_ref[2], rtol=1e-4)
        assert multi == (n == 25)


def test_terrain_height_and_material_field(device: str) -> None:
    """Depth is measured below z_s(x, y) and the material blends along x (basalt -> dry sand -> poppy)."""
    mats = tuple(MATERIAL_PRESETS[k] for k in ("basalt", "dry_sand", "poppy_seed"))
    terrain = terrain_transition(mats, (-0.2, 0.2), blend=0.1, base=terrain_sinusoid((0.01, 0.005), (0.7, 0.5)))
    model = make_contact_model(
        ContactRFT3DCfg(collider=g1_foot_box_cfg("sole", 3), at_rest="none"), W, F, device, terrain
    )
    model.set_materials(np.full(W, 1000.0), np.full(W, 0.2), np.full(W, 0.2))  # ignored: terrain sets materials
    feet = random_feet(4, tilt=0.2)
    run(model, feet)
    forces, depth = model.point_force.numpy(), model.point_depth.numpy()
    col = model.collider
    for w in range(W):
        for f in range(F):
            pts, nrm, vel = element_kinematics(col.points, col.normals, *(a[w, f] for a in feet[:4]))
            z_s = terrain_height(terrain, pts[:, 0], pts[:, 1])
            np.testing.assert_allclose(depth[w, f], z_s - pts[:, 2], atol=1e-6)
            m = terrain_material(terrain, pts[:, 0])
            ref = rft3d_forces(pts, nrm, vel, col.areas, rho_c=m[:, 0], mu_int=m[:, 1], mu_surf=m[:, 2], surface_z=z_s)
            ok = well_conditioned(nrm, vel, z_s - pts[:, 2])
            np.testing.assert_allclose(forces[w, f][ok], ref[ok], atol=1e-4 * max(np.abs(ref).max(), 1e-9))


def test_non_finite_inputs_give_zero_force_and_count(device: str) -> None:
    """NaN/inf foot states produce zero force for their elements, a counter, and no NaN anywhere."""
    model = make_contact_model(ContactRFT3DCfg(), W, F, device)
    feet = list(random_feet(6))
    feet[0][1, 0, 2] = np.nan
    feet[2][2, 1, 0] = np.inf
    wrench = run(model, tuple(feet))
    assert np.all(np.isfinite(wrench)) and np.all(np.isfinite(model.point_force.numpy()))
    np.testing.assert_array_equal(wrench[1, 0], 0.0)
    np.testing.assert_array_equal(wrench[2, 1], 0.0)
    assert model.nan_count.numpy()[0] == 2 * model.num_points


def test_compute_is_stateless_and_deterministic(device: str) -> None:
    """compute() leaves the state untouched and is bit-identical across calls; update_state advances it."""
    model = make_contact_model(ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 5)), W, F, device)
    feet = random_feet(10)
    first = run(model, feet)
    np.testing.assert_array_equal(model.depth_max.numpy(), 0.0)
    np.testing.assert_array_equal(run(model, feet), first)
    model.update_state(*foot_arrays(*feet))
    assert model.depth_max.numpy().max() > 0.0
    model.reset([0, 3])
    np.testing.assert_array_equal(model.depth_max.numpy()[[0, 3]], 0.0)


def test_set_materials_in_place_and_validated(device: str) -> None:
    """set_materials copies into the preallocated arrays (same pointer), updates eta, and rejects bad values."""
    model = make_contact_model(ContactRFT3DCfg(), W, F, device)
    ptr = model.rho_c.ptr
    model.set_materials([3000.0, 500.0], [1.0, 0.1], [0.5, 0.5], env_ids=np.array([1, 4]))
    assert model.rho_c.ptr == ptr
    np.testing.assert_allclose(model.rho_c.numpy()[[1, 4]], [3000.0, 500.0])
    np.testing.assert_allclose(model.eta.numpy()[1], 1.0, rtol=1e-6)
    with pytest.raises(ValueError, match=r"mu_int.*range"):
        model.set_materials(mu_int=np.full(W, 1.5))
    with pytest.raises(ValueError, match=r"rho_c.*range"):
        model.set_materials(rho_c=np.full(W, -1.0))
    cone = make_contact_model(ContactConeSingleCfg(), W, F, device)
    cone.set_materials(sigma_flat=np.full(W, 2e6), sigma_cone=np.full(W, 3e5))
    np.testing.assert_allclose(cone.sigma_flat.numpy(), 2e6)


def test_rigid_model_writes_zero(device: str) -> None:
    """The rigid baseline flags itself and writes zero wrenches."""
    model = make_contact_model(ContactRigidCfg(), W, F, device)
    assert model.is_rigid and not model.is_stateful
    assert make_contact_model(ContactConeSingleCfg(at_rest="none"), 1, 1, device).is_stateful
    assert not make_contact_model(ContactRFT3DCfg(at_rest="none"), 1, 1, device).is_stateful
    np.testing.assert_array_equal(run(model, random_feet(1)), 0.0)


def test_set_materials_keeps_eta_and_eta_log_in_step(device: str) -> None:
    """Host and device (torch) inputs give the same arrays; eta and eta_log follow a change of mu_int alone.

    eta = xi / xi_max and eta_log = ln(xi / xi_min) / ln(xi_max / xi_min) (materials.eta), evaluated in float32
    on the device: rtol 1e-5 covers a few float32 roundings of xi ~ 1e4-1e7 N/m^3 and of its logarithm.
    """
    torch = pytest.importorskip("torch")
    rho, mu, ms = np.array([3000.0, 500.0, 1800.0]), np.array([1.0, 0.1, 0.6]), np.array([0.5, 0.2, 0.9])
    ids = np.array([1, 4, 2])
    host = make_contact_model(ContactRFT3DCfg(), W, F, device)
    host.set_materials(rho, mu, ms, env_ids=ids)
    dev = make_contact_model(ContactRFT3DCfg(), W, F, device)
    as_t = lambda a: torch.as_tensor(a, dtype=torch.float32, device=wp.device_to_torch(device))  # noqa: E731
    dev.set_materials(as_t(rho), as_t(mu), as_t(ms), env_ids=torch.as_tensor(ids, device=as_t(rho).device))
    for name in ("rho_c", "mu_int", "mu_surf", "eta", "eta_log"):
        np.testing.assert_array_equal(getattr(dev, name).numpy(), getattr(host, name).numpy(), err_msg=name)
    host.set_materials(mu_int=[0.3], env_ids=[4])  # rho_c of world 4 stays 500
    mu_now = np.array([1.0, 0.3, 0.6])
    np.testing.assert_allclose(host.eta.numpy()[ids], eta(rho, mu_now), rtol=1e-5)
    np.testing.assert_allclose(host.eta_log.numpy()[ids], eta(rho, mu_now, "log"), rtol=1e-5)
    with pytest.raises(ValueError, match="unknown parameters"):
        dev.set_materials(sigma_flat=as_t(rho), env_ids=torch.as_tensor(ids, device=as_t(rho).device))
