# SPDX-License-Identifier: Apache-2.0
"""Hand-checked values of the gate's pure metrics (no simulator)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gmloco.train.gate.metrics import (
    circle_reference,
    course_finished_s,
    dtw_path_error,
    heading_drift_deg,
    swing_apex_heights,
    yaw_of_quat,
)


def test_heading_drift_wraps_across_pi() -> None:
    """A turn from 179 deg to -179 deg is a 2 deg drift, not 358 deg."""
    np.testing.assert_allclose(heading_drift_deg(math.radians(179.0), math.radians(-179.0)), 2.0, atol=1e-9)
    np.testing.assert_allclose(heading_drift_deg(0.3, 0.3), 0.0, atol=1e-12)


def test_yaw_of_quat_recovers_a_rotation_about_z() -> None:
    """A quaternion (cos(a/2), 0, 0, sin(a/2)) has yaw a."""
    a = np.array([-2.0, 0.0, 0.7, 3.0])
    q = np.stack([np.cos(a / 2), 0 * a, 0 * a, np.sin(a / 2)], axis=-1)
    np.testing.assert_allclose(yaw_of_quat(q), a, atol=1e-12)


def test_circle_reference_closes_after_one_period() -> None:
    """At 1 m/s and 0.5 rad/s: radius 2 m, back at the start after 4 pi s, 4 m across after 2 pi s."""
    t = np.array([0.0, 2 * math.pi, 4 * math.pi])
    path = circle_reference(np.array([1.0, -1.0]), math.pi / 2, 1.0, 0.5, t)
    # Heading +y: the circle's centre is 2 m to the left (-x) of the start, the far point at (1 - 4, -1).
    np.testing.assert_allclose(path, [[1.0, -1.0], [-3.0, -1.0], [1.0, -1.0]], atol=1e-12)


def test_circle_reference_zero_yaw_rate_is_a_line() -> None:
    """A zero yaw rate gives the line p(t) = p0 + v t along the heading."""
    path = circle_reference(np.zeros(2), 0.0, 2.0, 0.0, np.array([0.0, 1.5]))
    np.testing.assert_allclose(path, [[0.0, 0.0], [3.0, 0.0]], atol=1e-12)


def test_dtw_ignores_pace_and_measures_offset() -> None:
    """The reference walked at half pace (each point twice) scores 0; a line 5 cm to the side scores 0.05 m.

    Offset d: |p_i - q_j| = sqrt((x_i - x_j)^2 + d^2) >= d with equality on the diagonal, so the diagonal is the
    cheapest warping and the mean matched distance is d.
    """
    ref = circle_reference(np.zeros(2), 0.0, 1.0, 0.5, np.linspace(0.0, 10.0, 101))
    assert dtw_path_error(np.repeat(ref, 2, axis=0), ref) == 0.0
    line = circle_reference(np.zeros(2), 0.0, 1.0, 0.0, np.linspace(0.0, 5.0, 51))
    np.testing.assert_allclose(dtw_path_error(line + np.array([0.0, 0.05]), line), 0.05, rtol=1e-12)
    assert math.isnan(dtw_path_error(line[:0], line))


def test_swing_apex_heights_of_two_swings() -> None:
    """Two swings of 4 steps with apexes 0.08 m and 0.12 m; a 1-step flicker is not a swing."""
    h = np.array([0, 0.02, 0.08, 0.05, 0.01, 0, 0.03, 0, 0.04, 0.12, 0.06, 0.02, 0])
    contact = np.array([1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1]) > 0
    np.testing.assert_allclose(swing_apex_heights(h, contact, np.ones(13, bool)), [0.08, 0.12])


def _line(speed: float, yaw: float, dt: float = 0.02, seconds: float = 10.0) -> np.ndarray:
    """Positions [T, 2] [m] of a body walking from the origin at ``speed`` [m/s] along heading ``yaw`` [rad]."""
    t = dt * np.arange(1, round(seconds / dt) + 1)
    return np.stack([speed * t * math.cos(yaw), speed * t * math.sin(yaw)], axis=-1)


def test_course_rule_by_hand() -> None:
    """1 m/s on a 10 s, 1 m/s line with 20 % slack finishes at 8 s; at 0.7 m/s or 40 deg off it never does."""
    dt = 0.02
    ref = circle_reference(np.zeros(2), 0.0, 1.0, 0.0, dt * np.arange(501))
    np.testing.assert_allclose(course_finished_s(_line(1.0, 0.0), ref, dt, 0.2), 8.0, atol=dt)
    np.testing.assert_allclose(course_finished_s(_line(0.9, 0.0), ref, dt, 0.2), 8.0 / 0.9, atol=dt)
    assert course_finished_s(_line(0.7, 0.0), ref, dt, 0.2) is None  # 7 m of the 8 m needed
    # 25 deg off: 10 cos 25 = 9.06 m along the line, past 8 m; 40 deg off: 7.66 m, short of it.
    assert course_finished_s(_line(1.0, math.radians(25.0)), ref, dt, 0.2) is not None
    assert course_finished_s(_line(1.0, math.radians(40.0)), ref, dt, 0.2) is None
    assert course_finished_s(_line(0.7, 0.0), ref, dt, 0.35) is not None


def test_course_rule_is_mpms() -> None:
    """The gate's course rule gives the MPM evaluation's times on drifting, wobbling, stopping walks."""
    locomotion = pytest.importorskip("gmloco.eval.metrics.locomotion")
    dt, rng = 0.02, np.random.default_rng(3)
    for _ in range(20):
        speed, yaw_rate = rng.uniform(0.5, 2.0), rng.choice([0.0, rng.uniform(-0.5, 0.5)])
        ref, _ = locomotion.circular_path(speed, yaw_rate, 10.0, dt)
        heading = rng.normal(0.0, 0.3) + np.cumsum(rng.normal(0.0, 0.02, 500))
        step = rng.uniform(0.6, 1.1) * speed * dt * np.stack([np.cos(heading), np.sin(heading)], axis=-1)
        path = np.cumsum(step, axis=0) + rng.normal(0.0, 0.01, (500, 2))
        mine = course_finished_s(
            path, circle_reference(np.zeros(2), 0.0, speed, yaw_rate, dt * np.arange(501)), dt, 0.2
        )
        assert mine == locomotion.course_finished_at(path, ref, dt, 0.2)
