# SPDX-License-Identifier: Apache-2.0
"""Box-study metrics: pure numpy in, floats out."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

__all__ = [
    "SINKAGE_FLOOR",
    "TRAVEL_FLOOR",
    "metric_grf_profile_error",
    "metric_lateral_force",
    "metric_relative_error",
    "metric_sinkage",
    "metric_travel",
]

TRAVEL_FLOOR = 0.01
"""Denominator floor of the travel relative error [m] (1 cm: below it a relative error is meaningless)."""
SINKAGE_FLOOR = 0.005
"""Denominator floor of the sinkage relative error [m] (5 mm, a tenth of a 5 cm voxel)."""


def metric_travel(pos: np.ndarray, start: np.ndarray) -> float:
    """Return the horizontal distance between the final and the release CoM position [m].

    Args:
        pos: CoM positions over time [m], [T, 3].
        start: Release position [m], [3].
    """
    return float(np.linalg.norm(np.asarray(pos)[-1, :2] - np.asarray(start)[:2]))


def _quat_wxyz_to_mat(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def metric_sinkage(pos: np.ndarray, quat_wxyz: np.ndarray, half_height: float, surface_z: float = 0.0) -> float:
    """Return the final depth of the box's bottom-face centre below the free surface [m] (negative = above).

    Args:
        pos: Final CoM position [m], [3].
        quat_wxyz: Final orientation (w, x, y, z), [4].
        half_height: Half the box height [m].
        surface_z: Height of the undisturbed free surface [m].
    """
    bottom = np.asarray(pos, dtype=np.float64) - _quat_wxyz_to_mat(quat_wxyz) @ np.array([0.0, 0.0, half_height])
    return float(surface_z - bottom[2])


def metric_lateral_force(grf: np.ndarray, velocity_xy: tuple[float, float]) -> float:
    """Return the time-mean force perpendicular to the launch direction in the horizontal plane [N].

    Args:
        grf: Force of the medium on the box [N], [T, 3].
        velocity_xy: Launch velocity (v_x, v_y) [m/s]; the lateral axis is e_z x v_hat.
    """
    v = np.array([velocity_xy[0], velocity_xy[1]], dtype=np.float64)
    v /= max(np.linalg.norm(v), 1e-12)
    lateral = np.array([-v[1], v[0]])
    return float(np.mean(np.asarray(grf)[:, :2] @ lateral))


def metric_relative_error(value: npt.ArrayLike, reference: npt.ArrayLike, floor: float) -> np.ndarray:
    """Return |value - reference| / max(|reference|, floor) element-wise [-]."""
    value, reference = np.asarray(value, dtype=np.float64), np.asarray(reference, dtype=np.float64)
    return np.abs(value - reference) / np.maximum(np.abs(reference), floor)


def metric_grf_profile_error(grf: np.ndarray, reference: np.ndarray, weight: float) -> float:
    """Return the RMS over time and components of (grf - reference), in units of the box weight [-].

    Both series must be sampled at the same times (the study logs both at the MPM frame time); the shorter
    length is used.

    Args:
        grf: Model force [N], [T, 3].
        reference: MPM force [N], [T', 3].
        weight: Box weight m g [N].
    """
    n = min(len(grf), len(reference))
    diff = np.asarray(grf)[:n] - np.asarray(reference)[:n]
    return float(np.sqrt(np.mean(diff**2)) / weight)
