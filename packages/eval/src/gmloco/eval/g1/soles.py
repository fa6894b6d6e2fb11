# SPDX-License-Identifier: Apache-2.0
"""The G1's soles on the sand: sole boxes, which corners need sand, where they lie against the window and pelvis.

Also what the scene builds from besides the G1 facts of :mod:`gmloco.deploy.g1` (foot bodies, sole box, and mjlab's
MJCF, ``g1_mjcf_path``, named here too): MuJoCo Warp's constraint rows per robot and the quaternion helpers of the
pelvis frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gmloco.deploy.g1 import G1_SOLE_BOX_CENTER, G1_SOLE_BOX_HALF_EXTENTS, g1_mjcf_path
from gmloco.eval.metrics.locomotion import quat_wxyz_to_roll_pitch_yaw

__all__ = [
    "NJMAX_PER_ROBOT",
    "SOLE_NEAR_M",
    "SoleCfg",
    "g1_mjcf_path",
    "needs_sand",
    "quat_conj",
    "quat_rotate_inv",
    "sole_box_corners",
    "sole_reach",
    "soles_outside",
]


SOLE_NEAR_M = 0.02
"""A sole corner this close above the local sand surface, or below it, needs sand under it [m] (``needs_sand``)."""


def needs_sand(corners: np.ndarray, surface: np.ndarray, near: float = SOLE_NEAR_M) -> np.ndarray:
    """Which sole corners [R, 2, 8, 3] are within ``near`` of the sand surface [R, 2, 8] or below it, [R, 2, 8]."""
    return corners[..., 2] - surface <= near


def soles_outside(
    corners: np.ndarray, low: np.ndarray, frames: tuple[np.ndarray, np.ndarray, np.ndarray]
) -> np.ndarray:
    """Sole corners that need sand under them but lie outside their robot's sand window, per robot.

    Args:
        corners: World sole corners [m], [R, 2, 8, 3].
        low: The corners that need sand (``needs_sand``), [R, 2, 8].
        frames: The windows (``SandWindow.frames``): centres [R, 2] [m], headings [R] [rad], half extents [2] [m].

    Returns:
        Number of such corners per robot, [R] (0 when the soles are over sand or in the air).
    """
    centre, heading, half = frames
    c, s = np.cos(heading)[:, None, None], np.sin(heading)[:, None, None]
    dx, dy = corners[..., 0] - centre[:, None, None, 0], corners[..., 1] - centre[:, None, None, 1]
    u, v = c * dx + s * dy, -s * dx + c * dy
    out = (np.abs(u) > half[0]) | (np.abs(v) > half[1])
    return (out & low).reshape(len(corners), -1).sum(axis=1)


def sole_box_corners(sole: SoleCfg) -> np.ndarray:
    """The 8 corners of a sole box in its ankle-roll frame [m], [8, 3]."""
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    return np.array(sole.center) + signs * np.array(sole.half_extents)


def sole_reach(corners: np.ndarray, low: np.ndarray, base_q: np.ndarray) -> np.ndarray:
    """How far the sole corners that need sand lie from the pelvis, in its yaw frame (x forward), per robot.

    Args:
        corners: World sole corners [m], [R, 2, 8, 3].
        low: The corners that need sand (``needs_sand``), [R, 2, 8].
        base_q: Pelvis poses (position, quaternion x y z w), [R, 7].

    Returns:
        [R, 3]: reach behind the pelvis, ahead of it, and sideways (largest |y|) [m]; NaN for a robot whose soles
        all are in the air.
    """
    yaw = quat_wxyz_to_roll_pitch_yaw(base_q[:, [6, 3, 4, 5]])[:, 2]
    c, s = np.cos(yaw)[:, None, None], np.sin(yaw)[:, None, None]
    dx, dy = corners[..., 0] - base_q[:, None, None, 0], corners[..., 1] - base_q[:, None, None, 1]
    fwd, side = c * dx + s * dy, -s * dx + c * dy
    out = np.full((len(corners), 3), np.nan)
    some = low.reshape(len(corners), -1).any(axis=1)
    if not some.any():
        return out
    f = np.where(low, fwd, np.nan)[some].reshape(int(some.sum()), -1)
    sd = np.where(low, np.abs(side), np.nan)[some].reshape(int(some.sum()), -1)
    out[some] = np.stack([-np.nanmin(f, axis=1), np.nanmax(f, axis=1), np.nanmax(sd, axis=1)], axis=1)
    return out


# MuJoCo Warp constraint rows per robot: both soles on the rigid floor (8 corners x 2 soles x 4 pyramidal rows) plus
# joint limits of a fallen robot reached 93 on the H100 (the voxel-size probes: "nefc overflow" at 64, rows dropped).
NJMAX_PER_ROBOT = 160


def quat_rotate_inv(q_xyzw: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors [..., 3] by the inverse of unit quaternions (x, y, z, w) [..., 4]."""
    u, w = -np.asarray(q_xyzw)[..., :3], np.asarray(q_xyzw)[..., 3:4]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


@dataclass(frozen=True)
class SoleCfg:
    """Sole box of each foot, in the ankle-roll-link frame (covers the MJCF foot capsules)."""

    center: tuple[float, float, float] = G1_SOLE_BOX_CENTER
    """Box centre in the ankle-roll frame [m] (capsules span x in [-0.054, 0.132], sit at z = -0.025)."""
    half_extents: tuple[float, float, float] = G1_SOLE_BOX_HALF_EXTENTS
    """Half sizes [m]."""
    effective_mass: float | None = None
    """Mass MPM solves each foot's contact against [kg]; None = half the robot's mass (double stance)."""


def quat_conj(q_xyzw: np.ndarray) -> np.ndarray:
    """Conjugate of quaternions (x, y, z, w)."""
    return np.concatenate([-q_xyzw[..., :3], q_xyzw[..., 3:4]], axis=-1)
