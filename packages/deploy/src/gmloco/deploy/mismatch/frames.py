# SPDX-License-Identifier: Apache-2.0
"""Vectorised quaternion helpers (w, x, y, z; Hamilton convention, as MuJoCo and Unitree use)."""

from __future__ import annotations

import numpy as np

__all__ = ["quat_conj", "quat_from_roll_pitch", "quat_mul", "quat_rotate", "quat_tilt", "quat_to_mat"]


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a * b``, shapes [..., 4]."""
    aw, ax, ay, az = np.moveaxis(np.asarray(a, float), -1, 0)
    bw, bx, by, bz = np.moveaxis(np.asarray(b, float), -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def quat_conj(q: np.ndarray) -> np.ndarray:
    """Conjugate (inverse of a unit quaternion), shape [..., 4]."""
    return np.asarray(q, float) * np.array([1.0, -1.0, -1.0, -1.0])


def quat_to_mat(q: np.ndarray) -> np.ndarray:
    """Rotation matrices of unit quaternions, shape [..., 3, 3]."""
    w, x, y, z = np.moveaxis(np.asarray(q, float), -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=-2,
    )


def quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors ``v`` [..., 3] by quaternions ``q`` [..., 4]."""
    return np.einsum("...ij,...j->...i", quat_to_mat(q), v)


def quat_from_roll_pitch(roll: float, pitch: float) -> np.ndarray:
    """Quaternion of ``R_x(roll) R_y(pitch)``, shape [4]."""
    qx = np.array([np.cos(roll / 2), np.sin(roll / 2), 0.0, 0.0])
    qy = np.array([np.cos(pitch / 2), 0.0, np.sin(pitch / 2), 0.0])
    return quat_mul(qx, qy)


def quat_tilt(q: np.ndarray) -> np.ndarray:
    """Roll and pitch [rad] of orientations, shape [..., 2] (gravity direction in the body frame)."""
    g = np.einsum("...ji,j->...i", quat_to_mat(q), np.array([0.0, 0.0, -1.0]))
    return np.stack([np.arctan2(-g[..., 1], -g[..., 2]), np.arcsin(np.clip(g[..., 0], -1, 1))], axis=-1)
