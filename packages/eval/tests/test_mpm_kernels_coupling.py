# SPDX-License-Identifier: Apache-2.0
"""Coupling launchers: the collider velocity each hand-over scheme gives MPM, against numpy."""

from __future__ import annotations

import numpy as np
import pytest
import warp as wp

from gmloco.eval.mpm.kernels_coupling import hand_over_velocity

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
