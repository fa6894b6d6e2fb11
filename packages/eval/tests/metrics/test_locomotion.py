# SPDX-License-Identifier: Apache-2.0
"""Locomotion metrics of the MPM evaluation against hand-computed values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gmloco.eval.metrics.locomotion import (
    FailureCfg,
    circular_path,
    dtw_distance,
    episode_outcome,
    failure_step,
    metric_heading_error_deg,
    metric_path_error,
    metric_velocity_tracking_error,
    metric_yaw_tracking_error,
    quat_wxyz_to_roll_pitch_yaw,
    swing_clearance,
)


def _brute_dtw(a: np.ndarray, b: np.ndarray) -> float:
    """Textbook recursion, cell by cell."""
    n, m = len(a), len(b)
    d = np.full((n + 1, m + 1), np.inf)
    d[0, 0] = 0.0
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            d[i, j] = np.linalg.norm(a[i - 1] - b[j - 1]) + min(d[i - 1, j - 1], d[i - 1, j], d[i, j - 1])
    return float(d[n, m])


def test_dtw_hand_case() -> None:
    """Sequences a = [0, 1, 2], b = [0, 0, 1, 2]: the repeated 0 warps onto a[0] for free -> cost 0, path length 4."""
    total, length = dtw_distance(np.array([0.0, 1.0, 2.0]), np.array([0.0, 0.0, 1.0, 2.0]))
    assert total == 0.0 and length == 4


def test_dtw_hand_case_with_offset() -> None:
    """Sequences a = [0, 2], b = [1]: both points match 1, cost |0-1| + |2-1| = 2 over 2 pairs -> path error 1."""
    total, length = dtw_distance(np.array([[0.0], [2.0]]), np.array([[1.0]]))
    assert total == 2.0 and length == 2
    assert metric_path_error(np.array([[0.0], [2.0]]), np.array([[1.0]])) == 1.0


def test_dtw_matches_brute_force() -> None:
    """Random 2-D paths of unequal length: wavefront DTW equals the cell-by-cell recursion."""
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(13, 2)), rng.normal(size=(9, 2))
    assert math.isclose(dtw_distance(a, b)[0], _brute_dtw(a, b), rel_tol=1e-12)


def test_path_error_of_shifted_line() -> None:
    """Executed path = commanded straight line shifted sideways by 0.1 m -> path error 0.1 m."""
    xy, _ = circular_path(1.0, 0.0, 2.0, 0.1)
    assert math.isclose(metric_path_error(xy + np.array([0.0, 0.1]), xy), 0.1, rel_tol=1e-12)


def test_circular_path_geometry() -> None:
    """Speed 1 m/s, yaw rate 0.5 rad/s: radius 2 m about (0, 2); a full period 4 pi s closes the circle."""
    xy, yaw = circular_path(1.0, 0.5, 4.0 * math.pi, 4.0 * math.pi / 400)
    assert np.allclose(np.linalg.norm(xy - [0.0, 2.0], axis=1), 2.0)
    assert np.allclose(xy[0], 0.0) and np.allclose(xy[-1], 0.0, atol=1e-9)
    assert math.isclose(yaw[-1], 2.0 * math.pi)
    # a quarter turn: (r, r) = (2, 2)
    assert np.allclose(xy[100], [2.0, 2.0])


def test_tracking_errors() -> None:
    """Command 1 m/s, measured 0.8 then 1.3 -> MAE 0.25; planar error is the norm; alive steps cut the mean."""
    assert math.isclose(metric_velocity_tracking_error(np.array([1.0, 1.0]), np.array([0.8, 1.3])), 0.25)
    cmd = np.array([[1.0, 0.0], [1.0, 0.0], [1.0, 0.0]])
    meas = np.array([[1.0, 0.3], [0.6, 0.3], [9.0, 9.0]])
    assert math.isclose(metric_velocity_tracking_error(cmd, meas, alive_steps=2), (0.3 + 0.5) / 2)
    assert math.isclose(metric_yaw_tracking_error(np.zeros(4), np.array([0.1, -0.1, 0.2, 0.0])), 0.1)
    with pytest.raises(ValueError):
        metric_velocity_tracking_error(np.zeros(2), np.zeros(3))


def test_failure_rules() -> None:
    """Height 0.19 < 0.2 fails at step 2; tilt 0.8 > pi/4 fails at step 1; the earliest wins."""
    cfg = FailureCfg()
    h = np.array([0.7, 0.7, 0.19, 0.7])
    zero = np.zeros(4)
    assert failure_step(h, zero, zero, cfg) == (2, "base_height")
    assert failure_step(np.full(4, 0.7), zero, np.array([0.0, -0.8, 0.0, 0.0]), cfg) == (1, "tilt")
    assert failure_step(h, np.array([0.0, 0.8, 0.0, 0.0]), zero, cfg) == (1, "tilt")
    assert failure_step(np.full(4, 0.7), np.full(4, 0.78), zero, cfg) == (-1, "")


def test_episode_outcome() -> None:
    """Finish inside 10 s without a fall -> success; not finished -> timeout; fall before finishing -> fall."""
    n, dt = 600, 0.02  # 12 s of steps
    ok, zero = np.full(n, 0.7), np.zeros(n)
    assert episode_outcome(ok, zero, zero, dt, finished_at_s=9.5).success
    out = episode_outcome(ok, zero, zero, dt, finished_at_s=None)
    assert (out.success, out.reason, out.alive_steps) == (False, "timeout", n)
    assert episode_outcome(ok, zero, zero, dt, finished_at_s=10.5).reason == "timeout"
    low = ok.copy()
    low[100:] = 0.1  # falls at 2 s
    out = episode_outcome(low, zero, zero, dt, finished_at_s=9.0)
    assert (out.success, out.reason, out.alive_steps) == (False, "base_height", 100)
    # falling after the finish line still counts as success
    assert episode_outcome(low, zero, zero, dt, finished_at_s=1.0).success


def test_roll_pitch_yaw() -> None:
    """Rotations of 0.3 rad about x, y and z each map to the matching Euler angle."""
    for axis in range(3):
        q = np.zeros(4)
        q[0], q[1 + axis] = math.cos(0.15), math.sin(0.15)
        rpy = quat_wxyz_to_roll_pitch_yaw(q)
        assert np.allclose(rpy, np.eye(3)[axis] * 0.3)


def _gait(cycles: int, stance_low: float, apex: float) -> tuple[np.ndarray, np.ndarray]:
    """One foot alternating 10 loaded steps at ``stance_low`` [m] and 10 unloaded steps with a peak at ``apex`` [m]."""
    swing_h = stance_low + (apex - stance_low) * np.sin(np.linspace(0.0, math.pi, 10))
    h = np.concatenate([np.r_[np.full(10, stance_low), swing_h] for _ in range(cycles)])
    load = np.concatenate([np.r_[np.full(10, 300.0), np.zeros(10)] for _ in range(cycles)])
    return h, load


def test_swing_clearance_known_gait() -> None:
    """Two feet with known apex / stance depth; the last, open swing and flicker are not counted."""
    h0, l0 = _gait(3, -0.05, 0.08)  # apex 8 cm, lift 13 cm
    h1, l1 = _gait(3, -0.01, 0.02)  # apex 2 cm, lift 3 cm
    l1[12] = 0.0  # one-step flicker inside a stance... (inside a swing it changes nothing)
    l1[5] = 0.0  # ... and inside a stance: too short to count as a swing
    height, load = np.stack([h0, h1], axis=1), np.stack([l0, l1], axis=1)
    # each foot: swings at 10-19 and 30-39 end in a touchdown; the one at 50-59 is still open at the end
    out = swing_clearance(height, load)
    peak = float(np.sin(np.linspace(0.0, math.pi, 10)).max())  # the sampled swing peaks just below its apex
    assert out.swings == 4
    assert out.apex == pytest.approx(((-0.05 + 0.13 * peak) + (-0.01 + 0.03 * peak)) / 2)
    assert out.lift == pytest.approx((0.13 + 0.03) * peak / 2)


def test_swing_clearance_alive_cut_and_no_swing() -> None:
    """Steps after the fall do not count; a foot that never lifts gives NaN means and zero swings."""
    h, load = _gait(3, -0.02, 0.05)
    cut = swing_clearance(h[:, None], load[:, None], alive_steps=35)
    assert cut.swings == 1  # the swing at 30-39 has no touchdown before step 35
    still = swing_clearance(np.full((50, 2), -0.03), np.full((50, 2), 200.0))
    assert still.swings == 0 and math.isnan(still.apex) and math.isnan(still.lift)
    with pytest.raises(ValueError, match=r"\[T, F\]"):
        swing_clearance(h, load)


def test_course_progress_counts_along_the_course() -> None:
    """A straight 10 m course at 1 m/s: finished at 8 s (20 % slack), also 3 m off to the side; standing: never."""
    from gmloco.eval.metrics.locomotion import circular_path, course_finished_at

    dt = 0.02
    cmd, _ = circular_path(1.0, 0.0, 10.0, dt)
    walk = cmd[1:]  # the base one sample ahead of t = 0
    assert course_finished_at(walk, cmd, dt, 0.2) == pytest.approx(8.0, abs=dt)
    assert course_finished_at(walk + np.array([0.0, 3.0]), cmd, dt, 0.2) == pytest.approx(8.0, abs=dt)
    assert course_finished_at(np.zeros((500, 2)), cmd, dt, 0.2) is None


def test_heading_error_straight_drift_hand_computed() -> None:
    """w_cmd = 0, yaw 0, 0.1, 0.2, 0.3 rad: mean error 0.15 rad = 8.5944 deg; the first 2 steps alive: 2.8648 deg."""
    yaw = np.array([0.0, 0.1, 0.2, 0.3])
    np.testing.assert_allclose(metric_heading_error_deg(yaw, 0.0, 0.02), math.degrees(0.15), rtol=1e-12)
    np.testing.assert_allclose(metric_heading_error_deg(yaw, 0.0, 0.02, alive_steps=2), math.degrees(0.05))


def test_heading_error_circle_follows_the_integrated_command() -> None:
    """A turn at exactly w_cmd from any start heading, across the +-pi seam: 0; turning half as fast: w t / 2."""
    dt, w, n = 0.02, 0.5, 500
    t = np.arange(n) * dt
    exact = np.angle(np.exp(1j * (3.0 + w * t)))  # starts at 3 rad, wraps through pi
    assert metric_heading_error_deg(exact, w, dt) < 1e-9
    lagging = 3.0 + 0.5 * w * t  # error 0.5 w t_i, mean 0.5 w mean(t) = 0.25 * 4.99 rad
    np.testing.assert_allclose(metric_heading_error_deg(lagging, w, dt), math.degrees(0.25 * t.mean()), rtol=1e-9)


def test_heading_error_is_a_wrapped_angle() -> None:
    """An error of 350 degrees counts as 10 degrees (the shortest way round); an empty log is NaN."""
    yaw = np.radians([0.0, 350.0])
    np.testing.assert_allclose(metric_heading_error_deg(yaw, 0.0, 0.02), 5.0, rtol=1e-9)
    assert math.isnan(metric_heading_error_deg(np.array([]), 0.0, 0.02))
