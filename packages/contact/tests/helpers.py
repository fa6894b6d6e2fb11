# SPDX-License-Identifier: Apache-2.0
"""Test helpers (loaded by path: pytest runs with --import-mode=importlib): foot states, element kinematics."""

from __future__ import annotations

import numpy as np
import warp as wp

DEVICE = "cpu"


def random_rotations(rng: np.random.Generator, n: int, max_angle: float) -> np.ndarray:
    """Return n rotation matrices about random axes by angles up to ``max_angle`` [rad], [n, 3, 3]."""
    axis = rng.normal(size=(n, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    angle = rng.uniform(-max_angle, max_angle, n)
    k = np.zeros((n, 3, 3))
    k[:, 0, 1], k[:, 0, 2], k[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
    k -= k.transpose(0, 2, 1)
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1 - c) * k @ k


def foot_arrays(*arrays: np.ndarray) -> tuple[wp.array, ...]:
    """Convert (pos, rot, lin_vel, ang_vel, com) numpy arrays [W, F, ...] into float32 Warp arrays."""
    types = (wp.vec3, wp.mat33, wp.vec3, wp.vec3, wp.vec3)
    return tuple(wp.array(a.astype(np.float32), dtype=t, device=DEVICE) for a, t in zip(arrays, types, strict=True))


def element_kinematics(
    points_b: np.ndarray, normals_b: np.ndarray, pos: np.ndarray, rot: np.ndarray, vel: np.ndarray, ang: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return float64 world (points, normals, velocities) of one foot's elements from float32-rounded inputs."""
    pos, rot, vel, ang = (np.asarray(a, dtype=np.float32).astype(np.float64) for a in (pos, rot, vel, ang))
    r = points_b @ rot.T
    return pos + r, normals_b @ rot.T, vel + np.cross(ang, r)
