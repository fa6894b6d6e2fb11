# SPDX-License-Identifier: Apache-2.0
"""Pure metrics of the training gate: numpy traces in, floats out (no simulator)."""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "circle_reference",
    "dtw_path_error",
    "heading_drift_deg",
    "swing_apex_heights",
    "wrap_to_pi",
    "yaw_of_quat",
]


def wrap_to_pi(angle: np.ndarray | float) -> np.ndarray:
    """Return ``angle`` [rad] wrapped to [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2.0 * np.pi) - np.pi


def yaw_of_quat(quat_wxyz: np.ndarray) -> np.ndarray:
    """Return the yaw [rad] of unit quaternions (w, x, y, z), shape ``[..., 4]`` -> ``[...]`` (ZYX Euler)."""
    w, x, y, z = np.moveaxis(np.asarray(quat_wxyz, dtype=np.float64), -1, 0)
    return np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def heading_drift_deg(yaw_start: float, yaw_end: float) -> float:
    """Return |wrap(yaw_end - yaw_start)| [deg] for yaws [rad]."""
    return float(np.degrees(abs(wrap_to_pi(yaw_end - yaw_start))))


def circle_reference(
    xy0: np.ndarray, yaw0: float, speed: float, yaw_rate: float, times: np.ndarray
) -> np.ndarray:  # fmt: skip
    """Return the commanded path [T, 2] [m] of a body starting at ``xy0`` [m] with heading ``yaw0`` [rad].

    Constant forward speed v [m/s] and yaw rate w [rad/s] trace p(t) = p0 + R(yaw0) (v/w sin wt, v/w (1 - cos wt));
    w = 0 is the straight line p0 + R(yaw0) (v t, 0).
    """
    t = np.asarray(times, dtype=np.float64)
    if abs(yaw_rate) < 1e-12:
        local = np.stack([speed * t, np.zeros_like(t)], axis=-1)
    else:
        r = speed / yaw_rate
        local = np.stack([r * np.sin(yaw_rate * t), r * (1.0 - np.cos(yaw_rate * t))], axis=-1)
    c, s = math.cos(yaw0), math.sin(yaw0)
    rot = np.array([[c, -s], [s, c]])
    return np.asarray(xy0, dtype=np.float64)[None, :] + local @ rot.T


def course_finished_s(path: np.ndarray, reference: np.ndarray, dt: float, slack: float) -> float | None:
    """Return when the body passed ``1 - slack`` of the commanded path [s] (None: never); MPM's course rule.

    Progress is the reference sample nearest the body, searched forwards from the last one within 0.5 s of
    samples, so a walk that bends away from its course still progresses along it, only more slowly.

    Args:
        path: Body positions [T, 2] [m], sample k at time (k + 1) dt.
        reference: Commanded path [N, 2] [m] (``circle_reference`` at 0, dt, 2 dt, ...).
        dt: Sample period [s].
        slack: Fraction of the commanded path that may be left and still count as finished [-].
    """
    ref = np.asarray(reference, dtype=np.float64)
    idx, window, goal = 0, max(1, round(0.5 / dt)), (1.0 - slack) * (len(ref) - 1)
    for k, p in enumerate(np.asarray(path, dtype=np.float64)):
        idx += int(np.argmin(np.linalg.norm(ref[idx : idx + window] - p, axis=1)))
        if idx >= goal:
            return (k + 1) * dt
    return None


def dtw_path_error(path: np.ndarray, reference: np.ndarray) -> float:
    """Return the mean point distance [m] along the dynamic-time-warping alignment of two paths [N, 2], [M, 2].

    D(i, j) = |p_i - q_j| + min(D(i-1, j), D(i, j-1), D(i-1, j-1)); the error is D(N, M) divided by the number of
    matched pairs on the optimal warping path, so a path that is the reference walked at another pace scores 0.
    """
    p, q = np.asarray(path, dtype=np.float64), np.asarray(reference, dtype=np.float64)
    if len(p) == 0 or len(q) == 0:
        return float("nan")
    dist = np.linalg.norm(p[:, None, :] - q[None, :, :], axis=-1)
    n, m = dist.shape
    cost = np.full((n + 1, m + 1), np.inf)
    steps = np.zeros((n + 1, m + 1))
    cost[0, 0] = 0.0
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            options = (cost[i - 1, j], cost[i, j - 1], cost[i - 1, j - 1])
            k = int(np.argmin(options))
            prev = ((i - 1, j), (i, j - 1), (i - 1, j - 1))[k]
            cost[i, j] = dist[i - 1, j - 1] + options[k]
            steps[i, j] = steps[prev] + 1.0
    return float(cost[n, m] / steps[n, m])


def swing_apex_heights(
    height: np.ndarray, in_contact: np.ndarray, alive: np.ndarray, min_steps: int = 3
) -> list[float]:
    """Return the apex height [m] of every completed swing of one foot (see ``evaluation_ts.swing_apexes``).

    Args:
        height: Sole height above the free surface [m], ``[T]``.
        in_contact: Foot contact flags, ``[T]``.
        alive: Env alive flags, ``[T]``.
        min_steps: Shortest swing counted [steps].
    """
    from gmloco.train.evaluation_ts import swing_apexes

    return [float(height[t]) for t in swing_apexes(height, in_contact, alive, min_steps)]
