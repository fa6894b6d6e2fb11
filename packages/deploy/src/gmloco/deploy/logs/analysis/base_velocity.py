# SPDX-License-Identifier: Apache-2.0
"""Base velocity in the heading frame: from odometry when logged, else from leg kinematics.

Leg odometry (no base estimator on the robot): a stance foot is assumed fixed in the world, so the pelvis
velocity in the pelvis frame is ``v = -(dp/dt + omega x p)``, with ``p`` the foot position in the pelvis frame
(numpy FK of the logged joint angles), ``dp/dt`` its finite-difference derivative and ``omega`` the IMU gyro.
Stance feet are averaged; the result is rotated into the heading (yaw-free) frame with the IMU orientation and
smoothed over ``window_s``. Foot slip on sand biases it low (a slipping stance foot is not fixed), which is why
odometry (mocap, estimator, simulator truth) wins when present.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gmloco.deploy.g1 import G1_FEET
from gmloco.deploy.logs.analysis.kinematics import G1LegKinematics
from gmloco.deploy.logs.rotations import quat_rotate, quat_to_rpy

__all__ = ["BaseVelocityCfg", "heading_velocity_from_odometry", "leg_odometry_velocity", "smooth"]


@dataclass
class BaseVelocityCfg:
    """Settings of the base-velocity estimate."""

    window_s: float = 0.8
    """Moving-average window [s]; one gait cycle averages out the within-step oscillation."""


def _to_heading(quat: np.ndarray, v_body: np.ndarray) -> np.ndarray:
    """Rotate body-frame vectors into the heading (yaw-only) frame, [T, 4] x [T, 3] -> [T, 3]."""
    v_world = quat_rotate(quat, v_body)
    yaw = quat_to_rpy(quat)[:, 2]
    c, s = np.cos(yaw), np.sin(yaw)
    return np.stack([c * v_world[:, 0] + s * v_world[:, 1], -s * v_world[:, 0] + c * v_world[:, 1], v_world[:, 2]], 1)


def smooth(t: np.ndarray, x: np.ndarray, window_s: float) -> np.ndarray:
    """Centered moving average over ``window_s`` [s] along axis 0, NaN-aware."""
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    n = max(1, round(window_s / dt))
    kernel = np.ones(n)
    x2 = np.atleast_2d(x.T).T
    valid = np.isfinite(x2)
    num = np.stack([np.convolve(np.where(valid[:, c], x2[:, c], 0.0), kernel, "same") for c in range(x2.shape[1])], 1)
    den = np.stack([np.convolve(valid[:, c].astype(float), kernel, "same") for c in range(x2.shape[1])], 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = num / den
    return out.reshape(x.shape)


def heading_velocity_from_odometry(quat: np.ndarray, v_body: np.ndarray) -> np.ndarray:
    """Heading-frame base velocity [m/s] [T, 3] from odometry orientation and body-frame velocity."""
    return _to_heading(quat, v_body)


def leg_odometry_velocity(
    t: np.ndarray, q: np.ndarray, quat: np.ndarray, gyro: np.ndarray, stance: np.ndarray
) -> np.ndarray:
    """Heading-frame base velocity [m/s] [T, 3] from stance-leg kinematics (NaN when no foot is in stance).

    Args:
        t: Time [s], shape [T].
        q: Joint positions [rad], [T, 29].
        quat: Pelvis orientation (w, x, y, z), [T, 4].
        gyro: Pelvis angular velocity, pelvis frame [rad/s], [T, 3].
        stance: Stance flags (left, right), [T, 2].
    """
    v_sum = np.zeros((len(t), 3))
    count = np.zeros(len(t))
    for k, foot in enumerate(G1_FEET):
        p, _ = G1LegKinematics(foot).foot_pose(q)
        p_dot = np.gradient(p, t, axis=0)
        v = -(p_dot + np.cross(gyro, p))
        w = stance[:, k].astype(float)
        v_sum += v * w[:, None]
        count += w
    with np.errstate(invalid="ignore", divide="ignore"):
        v_body = v_sum / count[:, None]
    return _to_heading(quat, v_body)
