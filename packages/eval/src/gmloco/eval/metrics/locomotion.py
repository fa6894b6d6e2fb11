# SPDX-License-Identifier: Apache-2.0
"""Locomotion metrics of the MPM evaluation (GM-Loco paper definitions), pure numpy.

* Failure: base height < 0.2 m, |roll| or |pitch| > pi/4, or the course not finished within 10 s.
* Velocity tracking error: mean absolute error between commanded and measured base velocity [m/s]
  (mean over alive steps of |v_xy - v_cmd_xy|, both in the same frame).
* Yaw tracking error: mean |w_z - w_z_cmd| [rad/s] over alive steps.
* Path error: dynamic-time-warping distance between executed and commanded xy paths, normalised by the
  warping-path length (mean matched point distance [m]).
* Swing clearance: the highest point of each completed swing of a sole above the local surface [m], and its lift
  above the lowest point of the stance before it [m] (the paper's swing-clearance figure; on sand a foot must
  lift out of its own footprint before it can swing forward).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "EpisodeOutcome",
    "FailureCfg",
    "SwingClearance",
    "circular_path",
    "course_finished_at",
    "dtw_distance",
    "episode_outcome",
    "failure_step",
    "metric_heading_error_deg",
    "metric_path_error",
    "metric_velocity_tracking_error",
    "metric_yaw_tracking_error",
    "quat_wxyz_to_roll_pitch_yaw",
    "swing_clearance",
]


@dataclass(frozen=True)
class FailureCfg:
    """Failure rules of the paper."""

    min_base_height: float = field(default=0.2, metadata={"ge": 0})
    """Failure when the base (pelvis) is below this height above the sand surface [m]."""
    max_tilt: float = field(default=math.pi / 4, metadata={"gt": 0})
    """Failure when |roll| or |pitch| exceeds this [rad]."""
    time_limit_s: float = field(default=10.0, metadata={"gt": 0})
    """Failure when the course is not finished within this time [s]."""


@dataclass(frozen=True)
class EpisodeOutcome:
    """Result of one episode."""

    success: bool
    """Finished the course in time without falling."""
    reason: str
    """``"success"``, ``"base_height"``, ``"tilt"`` or ``"timeout"``."""
    alive_steps: int
    """Steps before the first failure (all steps if none)."""


def quat_wxyz_to_roll_pitch_yaw(quat_wxyz: np.ndarray) -> np.ndarray:
    """Return ZYX Euler angles (roll, pitch, yaw) [rad], [..., 3], of unit quaternions (w, x, y, z) [..., 4]."""
    q = np.asarray(quat_wxyz, dtype=np.float64)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    roll = np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0))
    yaw = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return np.stack([roll, pitch, yaw], axis=-1)


def failure_step(base_height: np.ndarray, roll: np.ndarray, pitch: np.ndarray, cfg: FailureCfg) -> tuple[int, str]:
    """Return (index of the first failing step, reason) or (-1, "") when no step fails.

    Args:
        base_height: Base height above the sand surface per step [m], [T].
        roll: Roll per step [rad], [T].
        pitch: Pitch per step [rad], [T].
        cfg: Failure rules.
    """
    low = np.asarray(base_height) < cfg.min_base_height
    tilt = (np.abs(np.asarray(roll)) > cfg.max_tilt) | (np.abs(np.asarray(pitch)) > cfg.max_tilt)
    bad = low | tilt
    if not bad.any():
        return -1, ""
    k = int(np.argmax(bad))
    return k, "base_height" if low[k] else "tilt"


def episode_outcome(
    base_height: np.ndarray,
    roll: np.ndarray,
    pitch: np.ndarray,
    dt: float,
    finished_at_s: float | None,
    cfg: FailureCfg | None = None,
) -> EpisodeOutcome:
    """Apply the paper's failure rules to one episode.

    Args:
        base_height: Base height above the sand per step [m], [T].
        roll: Roll per step [rad], [T].
        pitch: Pitch per step [rad], [T].
        dt: Step period [s].
        finished_at_s: Time the course end was reached [s], None if never.
        cfg: Failure rules (paper defaults).
    """
    cfg = cfg or FailureCfg()
    n = len(np.asarray(base_height))
    k, reason = failure_step(base_height, roll, pitch, cfg)
    fail_t = math.inf if k < 0 else k * dt
    if finished_at_s is not None and finished_at_s <= cfg.time_limit_s and finished_at_s < fail_t + 1e-12:
        # falling after the finish line does not count
        return EpisodeOutcome(True, "success", n if k < 0 else k)
    if k >= 0:
        return EpisodeOutcome(False, reason, k)
    return EpisodeOutcome(False, "timeout", n)


def _alive(n: int, alive_steps: int | None) -> slice:
    return slice(0, n if alive_steps is None else max(0, min(n, alive_steps)))


def metric_velocity_tracking_error(v_cmd: np.ndarray, v_meas: np.ndarray, alive_steps: int | None = None) -> float:
    """Mean absolute error |v_meas - v_cmd| [m/s] over the (alive) steps.

    Args:
        v_cmd: Commanded base velocity [m/s], [T] or [T, D] (D = 2 for planar velocity).
        v_meas: Measured base velocity in the same frame [m/s], same shape.
        alive_steps: Count only the first ``alive_steps`` steps (None: all).
    """
    c, m = np.asarray(v_cmd, dtype=np.float64), np.asarray(v_meas, dtype=np.float64)
    if c.shape != m.shape:
        raise ValueError(f"shape mismatch {c.shape} vs {m.shape}")
    s = _alive(len(c), alive_steps)
    err = np.abs(c[s] - m[s]) if c.ndim == 1 else np.linalg.norm(c[s] - m[s], axis=-1)
    return float(err.mean()) if err.size else float("nan")


def metric_yaw_tracking_error(wz_cmd: np.ndarray, wz_meas: np.ndarray, alive_steps: int | None = None) -> float:
    """Mean |w_z - w_z_cmd| [rad/s] over the (alive) steps."""
    return metric_velocity_tracking_error(np.ravel(wz_cmd), np.ravel(wz_meas), alive_steps)


def metric_heading_error_deg(
    yaw: np.ndarray, wz_cmd: float | np.ndarray, dt: float, alive_steps: int | None = None
) -> float:
    """Mean heading error |wrap(psi - psi_cmd)| [deg] over the (alive) steps: GM-Loco's yaw tracking error.

    The commanded heading integrates the commanded yaw rate from the start heading,
    psi_cmd(t_i) = psi(0) + sum_{j < i} w_cmd(t_j) dt (for a constant command, psi(0) + w_cmd i dt).

    Args:
        yaw: Measured base yaw psi [rad], [T] (any branch: differences are wrapped).
        wz_cmd: Commanded yaw rate [rad/s], scalar or [T].
        dt: Sample period [s].
        alive_steps: Count only the first ``alive_steps`` steps (None: all).
    """
    psi = np.ravel(np.asarray(yaw, dtype=np.float64))
    if not len(psi):
        return float("nan")
    w = np.broadcast_to(np.asarray(wz_cmd, dtype=np.float64), psi.shape)
    psi_cmd = psi[0] + np.concatenate([[0.0], np.cumsum(w[:-1]) * dt])
    err = np.abs(np.angle(np.exp(1j * (psi - psi_cmd))))[_alive(len(psi), alive_steps)]
    return float(np.degrees(err.mean())) if err.size else float("nan")


def dtw_distance(a: np.ndarray, b: np.ndarray) -> tuple[float, int]:
    """Dynamic time warping between two point sequences (Euclidean ground cost).

    O(N M) time and memory, vectorised over anti-diagonals (one numpy pass per diagonal).

    Args:
        a: Sequence [N, D] (or [N]).
        b: Sequence [M, D] (or [M]).

    Returns:
        (total cost of the optimal warping path, number of matched pairs on it).
    """
    x = np.asarray(a, dtype=np.float64)
    y = np.asarray(b, dtype=np.float64)
    x = x[:, None] if x.ndim == 1 else x
    y = y[:, None] if y.ndim == 1 else y
    n, m = len(x), len(y)
    if n == 0 or m == 0:
        raise ValueError("DTW needs non-empty sequences")
    cost = np.linalg.norm(x[:, None, :] - y[None, :, :], axis=-1)
    acc = np.full((n + 1, m + 1), np.inf)
    length = np.zeros((n + 1, m + 1), dtype=np.int64)
    acc[0, 0] = 0.0
    # wavefront over anti-diagonals i + j = k: every cell's three predecessors lie on diagonals k - 1, k - 2
    for k in range(2, n + m + 1):
        i = np.arange(max(1, k - m), min(n, k - 1) + 1)
        j = k - i
        cands = np.stack([acc[i - 1, j - 1], acc[i - 1, j], acc[i, j - 1]])  # diagonal first wins ties
        lens = np.stack([length[i - 1, j - 1], length[i - 1, j], length[i, j - 1]])
        best = np.argmin(cands, axis=0)
        cols = np.arange(len(i))
        acc[i, j] = cands[best, cols] + cost[i - 1, j - 1]
        length[i, j] = lens[best, cols] + 1
    return float(acc[n, m]), int(length[n, m])


def metric_path_error(executed_xy: np.ndarray, commanded_xy: np.ndarray) -> float:
    """DTW path error [m]: DTW cost normalised by the warping-path length (mean matched distance)."""
    total, length = dtw_distance(executed_xy, commanded_xy)
    return total / max(length, 1)


def circular_path(
    speed: float,
    yaw_rate: float,
    duration_s: float,
    dt: float,
    start_xy: tuple[float, float] = (0.0, 0.0),
    start_yaw: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Commanded path of a constant (forward speed, yaw rate) command: a circle of radius speed / |yaw_rate|.

    Args:
        speed: Forward speed in the body frame [m/s].
        yaw_rate: Commanded yaw rate [rad/s] (0: a straight line).
        duration_s: Length of the command [s].
        dt: Sample period [s].
        start_xy: Start position [m].
        start_yaw: Start heading [rad].

    Returns:
        (xy [T + 1, 2] in m, heading [T + 1] in rad) at t = 0, dt, ..., T dt.
    """
    t = np.arange(round(duration_s / dt) + 1) * dt
    yaw = start_yaw + yaw_rate * t
    if abs(yaw_rate) < 1e-12:
        dx, dy = speed * t * math.cos(start_yaw), speed * t * math.sin(start_yaw)
    else:
        r = speed / yaw_rate
        dx = r * (np.sin(yaw) - math.sin(start_yaw))
        dy = -r * (np.cos(yaw) - math.cos(start_yaw))
    xy = np.stack([start_xy[0] + dx, start_xy[1] + dy], axis=-1)
    return xy, yaw


def course_finished_at(xy: np.ndarray, commanded_xy: np.ndarray, dt: float, slack: float) -> float | None:
    """When the base passed ``1 - slack`` of the commanded path [s] (None: never).

    Progress is the commanded sample nearest the base, searched forwards from the last one within 0.5 s of
    samples (a circle revisits points), so a walk that bent away from the course still progresses along it.

    Args:
        xy: Executed base path [T, 2] [m], one sample per ``dt``.
        commanded_xy: Commanded path (``circular_path``) [N, 2] [m].
        dt: Sample period [s].
        slack: Fraction of the commanded path that may be left and still count as finished [-].
    """
    idx, window = 0, max(1, round(0.5 / dt))
    for t, p in enumerate(np.asarray(xy)):
        idx += int(np.argmin(np.linalg.norm(commanded_xy[idx : idx + window] - p, axis=1)))
        if idx >= (1.0 - slack) * (len(commanded_xy) - 1):
            return (t + 1) * dt
    return None


@dataclass(frozen=True)
class SwingClearance:
    """Swing statistics of one episode (NaN means where no swing completed)."""

    apex: float
    """Mean over completed swings of the sole's highest point above the local surface [m]."""
    lift: float
    """Mean over completed swings of the apex minus the lowest sole point of the stance before it [m]."""
    swings: int
    """Number of completed swings, all feet."""


def swing_clearance(
    height: np.ndarray, load: np.ndarray, alive_steps: int | None = None, threshold: float = 40.0, min_steps: int = 3
) -> SwingClearance:
    """Swing apex and lift of every completed swing of every foot.

    A swing is a run of at least ``min_steps`` steps with the foot's vertical load below ``threshold`` that ends
    in a touchdown within the alive steps (the last, open swing does not count). Its stance is the run of loaded
    steps before it; the first swing of a foot, which has no stance on record before it, counts for the apex only.

    Args:
        height: Lowest sole point above the local surface per step and foot [m], ``[T, F]`` (negative: sunk).
        load: Vertical ground force on each foot [N], ``[T, F]``.
        alive_steps: Steps that count (the episode's alive part); None: all.
        threshold: Load below which a foot is in swing [N].
        min_steps: Shortest swing counted [steps] (shorter runs are contact flicker).
    """
    height, load = np.asarray(height, dtype=float), np.asarray(load, dtype=float)
    if height.shape != load.shape or height.ndim != 2:
        raise ValueError(f"height and load must both be [T, F]; got {height.shape} and {load.shape}")
    n = height.shape[0] if alive_steps is None else min(alive_steps, height.shape[0])
    apexes: list[float] = []
    lifts: list[float] = []
    for f in range(height.shape[1]):
        h, swing = height[:n, f], load[:n, f] < threshold
        t, stance_low = 0, math.nan
        while t < n:
            end = t
            while end < n and swing[end] == swing[t]:
                end += 1
            if not swing[t]:
                stance_low = float(h[t:end].min())
            elif end < n and end - t >= min_steps:
                apex = float(h[t:end].max())
                apexes.append(apex)
                if math.isfinite(stance_low):
                    lifts.append(apex - stance_low)
            t = end
    return SwingClearance(apex=_mean_or_nan(apexes), lift=_mean_or_nan(lifts), swings=len(apexes))


def _mean_or_nan(values: list[float]) -> float:
    """Mean of ``values``; NaN for none."""
    return float(np.mean(values)) if values else math.nan
