# SPDX-License-Identifier: Apache-2.0
"""The sand's force on a walking robot from its momentum: a walk's ground force that no coupling log can alias.

On the MPM bed the only external forces on the G1 are gravity and the sand on its soles (frames after a fall are
dropped before this runs). Newton's second law for the whole robot then gives the sand's total force, averaged over
the two policy steps around frame k, from the logged pose and rates alone:

    F_k = M (c_dot[k+1] - c_dot[k-1]) / (2 dt) - M g,

with M the robot's mass, c its centre of mass, ``c_dot = J_com q_dot`` exact at every 50 Hz sample (the logged
pelvis twist and joint rates through the G1 model's centre-of-mass Jacobian) and g = (0, 0, -9.81) m/s^2. The
recorded per-foot force of the older MPM logs read one 5 ms frame of a force that alternates frame to frame
(``results/mpm_eval/coupling_chatter``); the momentum does not depend on that log.

While one foot is clear of the sand on frames k-1, k and k+1 (its logged force below
``MomentumForceCfg.contact_force`` and its sole's lowest corner no deeper than ``MomentumForceCfg.clear_depth``: a
foot still in its footprint may rest on the footprint's floor, and the aliased log reads a third of a load) the other
foot carries F_k and the clear foot none; otherwise the split is unknown and both feet's forces are NaN (a fit leaves
those frames out).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["MomentumForceCfg", "com_velocity", "foot_forces", "momentum_force", "total_force"]


@dataclass(frozen=True)
class MomentumForceCfg:
    """How the momentum's total force is given to the feet."""

    contact_force: float = 40.0
    """A foot whose logged force is below this may be clear of the sand (the MPM evaluation's contact rule) [N]."""
    clear_depth: float = 0.0
    """... and only if its sole's lowest corner is at most this deep below the bed's top [m]."""


def com_velocity(model: Any, qpos: np.ndarray, qvel: np.ndarray) -> np.ndarray:
    """Return the robot's centre-of-mass velocity [m/s], [T, 3], from generalized positions and velocities.

    Args:
        model: The G1 ``mujoco.MjModel`` (free base).
        qpos: Generalized positions, [T, nq] (base position and quaternion w, x, y, z, then the joints).
        qvel: Generalized velocities, [T, nv] (base linear velocity in the world frame, base angular velocity in the
            base frame, then the joint rates), as MuJoCo's free joint holds them.
    """
    import mujoco

    data = mujoco.MjData(model)
    jac = np.zeros((3, model.nv))
    out = np.zeros((len(qpos), 3))
    for k in range(len(qpos)):
        data.qpos[:] = qpos[k]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_jacSubtreeCom(model, data, jac, 0)
        out[k] = jac @ qvel[k]
    return out


def momentum_force(com_vel: np.ndarray, mass: float, gravity: np.ndarray, dt: float) -> np.ndarray:
    """Return ``F_k = M (c_dot[k+1] - c_dot[k-1]) / (2 dt) - M g`` [N], [T, 3] (ends: NaN).

    Args:
        com_vel: Centre-of-mass velocity per frame [m/s], [T, 3].
        mass: Robot mass M [kg].
        gravity: Gravity vector g [m/s^2], [3].
        dt: Frame time [s].
    """
    out = np.full_like(com_vel, np.nan)
    out[1:-1] = mass * ((com_vel[2:] - com_vel[:-2]) / (2.0 * dt) - np.asarray(gravity))
    return out


def total_force(model: Any, qpos: np.ndarray, qvel: np.ndarray, dt: float) -> np.ndarray:
    """Return the external non-gravity force on the robot [N], [T, 3], centred on each frame (ends: NaN).

    :func:`momentum_force` of :func:`com_velocity`, with the model's mass and gravity; ``dt`` is the frame time [s].
    """
    com_vel = com_velocity(model, qpos, qvel)
    return momentum_force(com_vel, float(model.body_subtreemass[0]), model.opt.gravity, dt)


def foot_forces(
    total: np.ndarray, logged: np.ndarray, depth: np.ndarray, cfg: MomentumForceCfg | None = None
) -> np.ndarray:
    """Return each foot's force [N], [T, 2, 3]: ``total`` on the stance foot in single support, NaN otherwise.

    Args:
        total: Total sand force per frame [N], [T, 3] (:func:`total_force`).
        logged: Logged force per frame and foot [N], [T, 2, 3]; only whether a foot bears load is read from it.
        depth: Depth of each sole's lowest corner below the bed's top per frame [m], [T, 2].
        cfg: The contact rule.
    """
    cfg = cfg or MomentumForceCfg()
    loaded = np.linalg.norm(logged, axis=-1) >= cfg.contact_force  # [T, 2]
    # The centred difference spans frames k-1..k+1: a foot counts as clear only if it is clear on all three.
    clear = ~loaded & (depth <= cfg.clear_depth)
    clear3 = clear.copy()
    clear3[1:-1] = clear[:-2] & clear[1:-1] & clear[2:]
    clear3[[0, -1]] = False
    out = np.full((len(total), 2, 3), np.nan)
    for f in range(2):
        single = clear3[:, 1 - f] & loaded[:, f]
        out[single, f] = total[single]
        out[single, 1 - f] = 0.0
    return out
