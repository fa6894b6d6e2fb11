# SPDX-License-Identifier: Apache-2.0
"""Hand-checked values of the gate's pure metrics (no simulator)."""

from __future__ import annotations

import math

import numpy as np

from gmloco.train.gate.metrics import (
    circle_reference,
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
