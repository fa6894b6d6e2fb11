# SPDX-License-Identifier: Apache-2.0
"""Floating-base state for replay resets: logged odometry when present, leg odometry otherwise.

Leg odometry (used when the log has no ``/odometry``): orientation is the IMU quaternion (the IMU sits in the
pelvis with no rotation in the MJCF; a misalignment hypothesis corrects it), angular velocity the gyro. With
that orientation and the measured joint angles, forward kinematics places the sole points relative to the
pelvis. The support foot is the lower one (with hysteresis); the pelvis height puts its lowest sole points
``penetration`` below the ground plane z = 0 (sinkage on sand is *not* observable from proprioception, so it is
an assumption reported as such). The base velocity is minus the support-point velocity from the joint
velocities and the gyro (the support point is assumed not to slip); the horizontal position is set to 0
(flat ground makes the dynamics independent of it). Requires ``mujoco`` (imported lazily).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gmloco.deploy.mismatch.frames import quat_rotate
from gmloco.deploy.mismatch.g1model import FIXED_BASE_HEIGHT, SOLE_POINTS

__all__ = ["BaseEstCfg", "BaseTrajectory", "estimate_base", "odometry_base", "welded_base"]


@dataclass
class BaseEstCfg:
    """Settings of the leg-odometry base estimator."""

    penetration: float = 0.0006
    """Assumed sinkage of the support foot's lowest sole points [m] (nominal ground under standing load)."""
    blend_height: float = 0.01
    """A foot this much above the lowest one gets zero weight in the velocity estimate [m]."""
    switch_margin: float = 0.004
    """Height advantage a foot needs to become the support foot [m] (hysteresis)."""
    contact_band: float = 0.004
    """Sole points within this height of the lowest one form the support patch [m]."""


@dataclass
class BaseTrajectory:
    """Pelvis state per sample, in MuJoCo free-joint conventions."""

    pos: np.ndarray
    """Pelvis position, world [m], shape [N, 3]."""
    quat: np.ndarray
    """Pelvis orientation (w, x, y, z), shape [N, 4]."""
    linvel: np.ndarray
    """Pelvis linear velocity, world frame [m/s], shape [N, 3]."""
    angvel: np.ndarray
    """Pelvis angular velocity, pelvis frame [rad/s], shape [N, 3]."""
    foot_height: np.ndarray
    """Lowest sole-point height per foot (left, right) [m], shape [N, 2]."""
    source: str
    """``"odometry"``, ``"leg_odometry"`` or ``"welded"`` (a gantry or fixed pelvis)."""


def _foot_ids(model: Any) -> list[int]:
    """Body ids of the left and right ankle-roll links."""
    return [model.body(f"{s}_ankle_roll_link").id for s in ("left", "right")]


def _sole_world(data: Any, body: int) -> np.ndarray:
    """Sole points of one foot in world coordinates [m], shape [8, 3]."""
    return data.xpos[body] + SOLE_POINTS @ data.xmat[body].reshape(3, 3).T


def estimate_base(
    model: Any, q: np.ndarray, dq: np.ndarray, quat: np.ndarray, omega: np.ndarray, cfg: BaseEstCfg
) -> BaseTrajectory:
    """Estimate the pelvis state by leg odometry (see module docstring).

    Args:
        model: Nominal ``mujoco.MjModel``.
        q: Joint positions (true, i.e. offset-corrected) [rad], shape [N, 29].
        dq: Joint velocities [rad/s], shape [N, 29].
        quat: Pelvis orientation (w, x, y, z), shape [N, 4].
        omega: Pelvis angular velocity, pelvis frame [rad/s], shape [N, 3].
        cfg: Estimator settings.
    """
    import mujoco

    data = mujoco.MjData(model)
    feet = _foot_ids(model)
    n = len(q)
    z = np.zeros(n)
    vel = np.zeros((n, 3))
    fh = np.zeros((n, 2))
    jacp = np.zeros((3, model.nv))
    support = 0
    for k in range(n):
        data.qpos[:3] = 0.0
        data.qpos[3:7] = quat[k]
        data.qpos[7:] = q[k]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        soles = [_sole_world(data, b) for b in feet]
        low = np.array([s[:, 2].min() for s in soles])
        if low[1 - support] < low[support] - cfg.switch_margin:
            support = 1 - support
        z[k] = -low[support] - cfg.penetration
        qv = np.concatenate([np.zeros(3), omega[k], dq[k]])
        # Both feet near the ground (double support) share the no-slip assumption, weighted by height.
        w = np.clip(1.0 - (low - low.min()) / cfg.blend_height, 0.0, 1.0)
        for f in (0, 1):
            if w[f] > 0:
                pts = soles[f]
                patch = pts[pts[:, 2] < low[f] + cfg.contact_band].mean(axis=0)
                mujoco.mj_jac(model, data, jacp, None, patch, feet[f])
                vel[k] -= w[f] / w.sum() * (jacp @ qv)
        fh[k] = low - low[support] - cfg.penetration
    pos = np.zeros((n, 3))  # x, y stay 0: flat ground makes the dynamics translation invariant
    pos[:, 2] = z
    return BaseTrajectory(pos, np.asarray(quat, float), vel, np.asarray(omega, float), fh, "leg_odometry")


def odometry_base(
    model: Any, q: np.ndarray, rec_pos: np.ndarray, rec_quat: np.ndarray, v_body: np.ndarray, w_body: np.ndarray
) -> BaseTrajectory:
    """Wrap logged odometry (body-frame velocities) as a :class:`BaseTrajectory`, adding foot heights by FK."""
    import mujoco

    data = mujoco.MjData(model)
    feet = _foot_ids(model)
    fh = np.zeros((len(q), 2))
    for k in range(len(q)):
        data.qpos[:3] = rec_pos[k]
        data.qpos[3:7] = rec_quat[k]
        data.qpos[7:] = q[k]
        mujoco.mj_kinematics(model, data)
        fh[k] = [_sole_world(data, b)[:, 2].min() for b in feet]
    return BaseTrajectory(
        np.asarray(rec_pos, float),
        np.asarray(rec_quat, float),
        quat_rotate(rec_quat, v_body),
        np.asarray(w_body, float),
        fh,
        "odometry",
    )


def welded_base(quat: np.ndarray) -> BaseTrajectory:
    """Pose of a welded pelvis per segment: the mean of its orientation samples, at rest at ``FIXED_BASE_HEIGHT``.

    A held pelvis touches nothing but its support, so its position does not enter the dynamics (uniform gravity);
    only its orientation does (the direction of gravity in the pelvis frame).

    Args:
        quat: Pelvis orientation samples (w, x, y, z) over each segment, shape [S, W, 4].
    """
    q = np.asarray(quat, float)
    q = q * np.where(np.sum(q * q[:, :1], axis=-1, keepdims=True) < 0.0, -1.0, 1.0)  # one hemisphere per row
    mean = q.mean(axis=1)
    mean /= np.linalg.norm(mean, axis=1, keepdims=True)
    s = len(mean)
    pos = np.zeros((s, 3))
    pos[:, 2] = FIXED_BASE_HEIGHT
    return BaseTrajectory(pos, mean, np.zeros((s, 3)), np.zeros((s, 3)), np.zeros((s, 2)), "welded")
