# SPDX-License-Identifier: Apache-2.0
"""Coupling launchers: the collider velocity each hand-over scheme gives MPM (against numpy), the sand wrench on a body."""

from __future__ import annotations

from typing import Any

import newton
import numpy as np
import pytest
import warp as wp

from gmloco.eval.mpm.kernels_coupling import eval_body_sand_wrench, hand_over_velocity

G = (0.0, 0.0, -9.81)
DT = 0.01


@pytest.fixture
def bodies() -> dict[str, np.ndarray]:
    """Two bodies: poses (one rotated 90 deg about z), velocities, lagged wrenches, inverse mass and inertia."""
    rng = np.random.default_rng(0)
    s = np.sqrt(0.5)
    return {
        "q": np.array([[0, 0, 0.1, 0, 0, 0, 1], [1, 0, 0.1, 0, 0, s, s]], dtype=np.float32),
        "qd": rng.normal(size=(2, 6)).astype(np.float32),
        "w": rng.normal(scale=100.0, size=(2, 6)).astype(np.float32),
        "inv_m": np.array([1 / 35.0, 0.5], dtype=np.float32),
        "inv_i": np.stack([np.diag([1.0, 2.0, 3.0]), np.diag([0.5, 0.5, 4.0])]).astype(np.float32),
    }


def _run(scheme: str, b: dict[str, np.ndarray]) -> np.ndarray:
    out = wp.zeros(2, dtype=wp.spatial_vectorf, device="cpu")  # = wp.spatial_vector, typed as a class
    hand_over_velocity(
        scheme,
        G,
        wp.array(b["inv_m"], dtype=float, device="cpu"),
        wp.array(b["inv_i"], dtype=wp.mat33, device="cpu"),
        DT,
        wp.array(b["q"], dtype=wp.transform, device="cpu"),
        wp.array(b["qd"], dtype=wp.spatial_vector, device="cpu"),
        wp.array(b["w"], dtype=wp.spatial_vector, device="cpu"),
        out,
    )
    return out.numpy()


def test_predict_adds_one_frame_of_gravity(bodies: dict[str, np.ndarray]) -> None:
    """predict: linear velocity + g dt, angular velocity unchanged, wrench ignored."""
    want = bodies["qd"].copy()
    want[:, :3] += np.array(G) * DT
    np.testing.assert_allclose(_run("predict", bodies), want, rtol=0, atol=1e-6)


def test_rewind_removes_the_lagged_wrench(bodies: dict[str, np.ndarray]) -> None:
    """rewind: qd - dt M^-1 w, the angular part through the world-frame inverse inertia R I^-1 R^T."""
    want = bodies["qd"].astype(np.float64).copy()
    want[:, :3] -= DT * bodies["inv_m"][:, None] * bodies["w"][:, :3]
    rot = [np.eye(3), np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])]  # the poses' rotations
    for b in range(2):
        want[b, 3:] -= DT * rot[b] @ bodies["inv_i"][b] @ rot[b].T @ bodies["w"][b, 3:]
    np.testing.assert_allclose(_run("rewind", bodies), want, rtol=0, atol=1e-5)


def test_actual_copies_and_unknown_scheme_is_refused(bodies: dict[str, np.ndarray]) -> None:
    """actual: the velocity as it is; an unknown scheme raises with the valid names."""
    np.testing.assert_array_equal(_run("actual", bodies), bodies["qd"])
    with pytest.raises(ValueError, match="predict"):
        _run("backward", bodies)


def _free_body_model(com: tuple[float, float, float], q: np.ndarray) -> Any:
    """One free 2 kg body, isotropic inertia 0.02 kg m^2, CoM off its origin, no gravity, no contacts."""
    b = newton.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    body = b.add_body(
        xform=wp.transform(wp.vec3(*q[:3]), wp.quat(*q[3:])),
        mass=2.0,
        com=wp.vec3(*com),
        inertia=wp.mat33(np.eye(3) * 0.02),
    )
    b.add_shape_box(body, hx=0.05, hy=0.05, hz=0.05, cfg=newton.ModelBuilder.ShapeConfig(density=0.0))
    return b.finalize(device="cpu")


def test_sand_wrench_moves_a_body_as_the_node_force_would() -> None:
    """Node force F at p -> wrench (F, (p - c) x F) -> SolverMuJoCo: dv = F dt / m and dw = I^-1 ((p - c) x F) dt.

    Guards the convention the G1 and box scenes rely on: Newton's ``body_f`` is a force at the CoM plus a torque, in
    world frame; a wrench about the body origin, or in body frame, would turn the body differently.
    """
    s = np.sqrt(0.5)
    q = np.array([0.3, -0.2, 1.0, 0.0, 0.0, s, s])  # rotated 90 deg about z: the body-frame CoM offset turns
    com_body = (0.1, 0.02, -0.03)
    model = _free_body_model(com_body, q)
    s0, s1 = model.state(), model.state()
    newton.eval_fk(model, model.joint_q, model.joint_qd, s0)
    f = np.array([3.0, -1.0, 40.0])
    p = np.array([0.45, -0.1, 0.95])
    dt, mpm_dt = 1e-3, 0.01
    wrench = wp.zeros(1, dtype=wp.spatial_vectorf, device="cpu")
    impulses = (
        wp.array([f * mpm_dt], dtype=wp.vec3, device="cpu"),
        wp.array([p], dtype=wp.vec3, device="cpu"),
        wp.array([0], dtype=int, device="cpu"),
    )
    eval_body_sand_wrench(wp.array([0], dtype=int, device="cpu"), model.body_com, mpm_dt, impulses, s0.body_q, wrench)
    wp.copy(s0.body_f, wrench)
    newton.solvers.SolverMuJoCo(model).step(s0, s1, model.control(), None, dt)
    com_world = q[:3] + np.array([-com_body[1], com_body[0], com_body[2]])  # R_z(90) applied to the offset
    qd = s1.body_qd.numpy()[0]
    np.testing.assert_allclose(qd[:3], f * dt / 2.0, rtol=1e-3, atol=1e-6)
    np.testing.assert_allclose(qd[3:], np.cross(p - com_world, f) * dt / 0.02, rtol=1e-3, atol=1e-5)
