# SPDX-License-Identifier: Apache-2.0
"""Resampling onto a common time base: linear states, held commands, quaternions, gaps."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gmloco.deploy.logs import AlignCfg, read_log, resample


def test_linear_signal_is_reproduced_exactly() -> None:
    """Linear interpolation of a linear ramp is exact at any grid point (up to float rounding)."""
    t_src = np.arange(0, 1.0001, 0.01)
    v = 3.0 * t_src[:, None] + np.array([0.0, 1.0])
    t = np.linspace(0, 1, 37)
    np.testing.assert_allclose(resample(t_src, v, t, "linear"), 3.0 * t[:, None] + np.array([0.0, 1.0]), atol=1e-12)


def test_hold_uses_last_value_and_nan_before_first() -> None:
    """Zero-order hold: value of the last sample at or before t; NaN before the first sample."""
    out = resample(np.array([0.1, 0.3]), np.array([1.0, 2.0]), np.array([0.0, 0.1, 0.2, 0.3, 0.5]), "hold")
    np.testing.assert_array_equal(out, [np.nan, 1.0, 1.0, 2.0, 2.0])


def test_gap_becomes_nan() -> None:
    """No interpolation across a gap longer than max_gap (dropped data must not look like data)."""
    out = resample(np.array([0.0, 0.01, 0.5, 0.51]), np.arange(4.0), np.array([0.005, 0.25, 0.505]), "linear", 0.1)
    np.testing.assert_allclose(out, [0.5, np.nan, 2.5])


def test_quaternion_sign_flip_is_interpolated_on_the_short_arc() -> None:
    """Interpolate a sign-flipped quaternion pair: q and -q are the same rotation: a sign flip between samples must not pass through zero."""
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    q1 = -np.array([np.cos(0.05), 0.0, 0.0, np.sin(0.05)])  # 0.1 rad yaw, stored with the opposite sign
    out = resample(np.array([0.0, 1.0]), np.stack([q0, q1]), np.array([0.5]), "quat", max_gap=2.0)
    np.testing.assert_allclose(np.linalg.norm(out, axis=1), 1.0)
    np.testing.assert_allclose(abs(out[0, 3]), np.sin(0.025), atol=1e-4)  # half-way yaw (nlerp, small angle)


def test_aligned_log_has_common_time_base(synthetic_log: Path) -> None:
    """All signals share one grid; the 50 Hz command is held onto the 100 Hz grid."""
    log = read_log(synthetic_log)
    a = log.aligned(AlignCfg(rate_hz=100.0))
    np.testing.assert_allclose(np.diff(a.t), 0.01, atol=1e-12)
    assert all(v.shape[0] == len(a.t) for v in a.signals.values())
    assert a["lowstate.q"].shape == (len(a.t), 29)
    t_cmd, vx = log.signal("command.lin_vel_x")
    expected = vx[np.searchsorted(t_cmd, a.t + 1e-12, side="right") - 1]
    np.testing.assert_array_equal(a["command.lin_vel_x"], expected)
    np.testing.assert_array_equal(a.joint("left_knee_joint", "lowstate.q"), a["lowstate.q"][:, 3])
