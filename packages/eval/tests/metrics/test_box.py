# SPDX-License-Identifier: Apache-2.0
"""Box-study metrics against hand-computed values."""

from __future__ import annotations

import math

import numpy as np

from gmloco.eval.metrics.box import (
    metric_grf_profile_error,
    metric_lateral_force,
    metric_relative_error,
    metric_sinkage,
    metric_travel,
)


def test_travel_is_horizontal_distance() -> None:
    """Start (0, 0, 0.2), end (0.3, 0.4, 0.1): travel = 0.5 m (3-4-5), z ignored."""
    pos = np.array([[0.0, 0.0, 0.2], [0.3, 0.4, 0.1]])
    assert math.isclose(metric_travel(pos, np.array([0.0, 0.0, 0.2])), 0.5)


def test_sinkage_of_pitched_box() -> None:
    """CoM at z = 0.05, pitched 90 deg about y: the bottom face centre is at x offset, z = 0.05 -> sinkage -0.05."""
    q = np.array([math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0])
    assert math.isclose(metric_sinkage(np.array([0.0, 0.0, 0.05]), q, 0.1), -0.05, abs_tol=1e-12)
    # upright: bottom at 0.05 - 0.1 = -0.05 -> sinkage 0.05
    assert math.isclose(metric_sinkage(np.array([0.0, 0.0, 0.05]), np.array([1.0, 0, 0, 0]), 0.1), 0.05)


def test_lateral_force_and_errors() -> None:
    """Launch along +x: lateral axis +y; mean F_y = 2 N. Relative error with floor; RMS in weight units."""
    grf = np.array([[-5.0, 1.0, 300.0], [-3.0, 3.0, 340.0]])
    assert math.isclose(metric_lateral_force(grf, (1.0, 0.0)), 2.0)
    np.testing.assert_allclose(metric_relative_error([0.12, 0.003], [0.1, 0.001], 0.005), [0.2, 0.4])
    # diff = (0, 0, 10) at both samples -> RMS over 6 numbers = sqrt(200 / 6); / weight 100
    ref = grf - np.array([0.0, 0.0, 10.0])
    assert math.isclose(metric_grf_profile_error(grf, ref, 100.0), math.sqrt(200 / 6) / 100)
