# SPDX-License-Identifier: Apache-2.0
"""The gyro-vs-attitude-rate channel: zero for a consistent IMU, the bias for a biased gyro (closed forms)."""

from __future__ import annotations

import numpy as np

from gmloco.deploy.mismatch.frames import quat_from_roll_pitch, quat_mul
from gmloco.deploy.mismatch.replay import attitude_rate_residual


def _spin(omega: np.ndarray, n: int, dt: float) -> np.ndarray:
    """Quaternions of a body turning at a constant body-frame rate ``omega`` [rad/s]: q(t) = exp(omega t / 2)."""
    w = np.linalg.norm(omega)
    t = np.arange(n) * dt
    return np.concatenate([np.cos(w * t / 2)[:, None], np.sin(w * t / 2)[:, None] * omega / w], axis=1)


def test_consistent_imu_gives_zero_and_bias_gives_bias() -> None:
    """Constant rate 0.7 rad/s: residual 0 to round-off; a gyro bias b shows up as exactly b."""
    dt, n = 0.002, 400
    omega = np.array([0.3, -0.5, 0.4])
    quat = _spin(omega, n, dt)
    gyro = np.tile(omega, (n, 1))
    # exact rotation-vector inverse of q(t) = exp(omega t / 2): error only from float64 round-off
    np.testing.assert_allclose(attitude_rate_residual(quat, gyro, dt, 8), 0.0, atol=1e-9)
    bias = np.array([0.03, -0.02, 0.015])
    np.testing.assert_allclose(attitude_rate_residual(quat, gyro + bias, dt, 8), np.tile(bias, (n, 1)), atol=1e-9)


def test_mounting_rotation_cancels() -> None:
    """A constant IMU mounting rotation R: quat q R and gyro R^T omega stay consistent (residual 0)."""
    dt, n = 0.002, 300
    omega = np.array([0.2, 0.6, -0.1])
    qm = quat_from_roll_pitch(0.03, -0.04)
    quat = quat_mul(_spin(omega, n, dt), np.tile(qm, (n, 1)))
    w, x, y, z = qm
    rot = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    gyro = np.tile(rot.T @ omega, (n, 1))
    np.testing.assert_allclose(attitude_rate_residual(quat, gyro, dt, 8), 0.0, atol=1e-9)
