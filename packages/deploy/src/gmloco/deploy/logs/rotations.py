# SPDX-License-Identifier: Apache-2.0
"""Quaternion helpers, (w, x, y, z) convention as in MuJoCo and the Unitree IMU, vectorized over leading axes."""

from __future__ import annotations

import numpy as np

__all__ = [
    "axis_angle_matrix",
    "quat_normalize",
    "quat_rotate",
    "quat_rotate_inv",
    "quat_to_matrix",
    "quat_to_rpy",
]


def quat_normalize(q: np.ndarray) -> np.ndarray:
    """Return unit quaternions, shape [..., 4]."""
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices of (w, x, y, z) quaternions, shape [..., 4] -> [..., 3, 3]."""
    w, x, y, z = np.moveaxis(quat_normalize(np.asarray(q, dtype=np.float64)), -1, 0)
    r = np.stack(
        [
            1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
        ],
        axis=-1,
    )  # fmt: skip
    return r.reshape(*r.shape[:-1], 3, 3)


def quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate body-frame vectors into the world frame, [..., 4] x [..., 3] -> [..., 3]."""
    return np.einsum("...ij,...j->...i", quat_to_matrix(q), v)


def quat_rotate_inv(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate world-frame vectors into the body frame, [..., 4] x [..., 3] -> [..., 3]."""
    return np.einsum("...ji,...j->...i", quat_to_matrix(q), v)


def quat_to_rpy(q: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw [rad] (intrinsic Z-Y-X, as Unitree's ``imu_state.rpy``), [..., 4] -> [..., 3]."""
    w, x, y, z = np.moveaxis(quat_normalize(np.asarray(q, dtype=np.float64)), -1, 0)
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.stack([roll, pitch, yaw], axis=-1)


def axis_angle_matrix(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices about a fixed unit ``axis`` [3] by ``angle`` [rad], shape [N] -> [N, 3, 3] (Rodrigues)."""
    a = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1 - c) * (k @ k)
