# SPDX-License-Identifier: Apache-2.0
"""Gait metrics on hand-computable inputs."""

from __future__ import annotations

import numpy as np

from gmloco.deploy.logs.analysis import stance_ankle_torque, swing_clearance, velocity_tracking


def test_swing_clearance_hand_computed() -> None:
    """Peak sole height over the stance foot during each swing.

    Left swings twice with apexes 4 cm and 6 cm (triangular profiles); right never swings: two rows,
    clearance 0.04 and 0.06 m at the apex times 0.3 s and 0.8 s.
    """
    t = np.arange(0, 1.2, 0.1)
    rel = np.zeros((len(t), 2))
    rel[2:5, 0] = [0.02, 0.04, 0.02]
    rel[7:10, 0] = [0.03, 0.06, 0.03]
    stance = rel < 0.01
    rows = swing_clearance(t, rel, stance)
    assert [r["foot"] for r in rows] == ["left", "left"]
    np.testing.assert_allclose([r["clearance"] for r in rows], [0.04, 0.06])
    np.testing.assert_allclose([r["t_peak"] for r in rows], [0.3, 0.8])


def test_stance_ankle_torque_hand_computed() -> None:
    """Peak, mean and trapezoid impulse of the ankle torque over one complete stance.

    Stance samples 2..5 (t = 0.2..0.5 s) with torque 10, 30, 20, 0 N*m: peak 30, mean 15,
    impulse = 0.1 * ((10+30)/2 + (30+20)/2 + (20+0)/2) = 5.5 N*m*s.
    """
    t = np.arange(0, 0.8, 0.1)
    tau = np.zeros((len(t), 2))
    tau[2:6, 0] = [10, 30, 20, 0]
    stance = np.zeros((len(t), 2), bool)
    stance[2:6, 0] = True
    rows = stance_ankle_torque(t, tau, stance)
    assert len(rows) == 1 and rows[0]["foot"] == "left"
    np.testing.assert_allclose([rows[0]["peak_abs"], rows[0]["mean"], rows[0]["impulse"]], [30, 15, 5.5])


def test_velocity_tracking_per_command_segment() -> None:
    """Two command segments; the first second after each change is excluded (settling)."""
    t = np.arange(0, 6, 0.01)
    cmd = np.where(t < 3, 0.2, 0.5)
    v = np.where(t < 3, 0.25, 0.4)
    v[(t >= 3) & (t < 4)] = 10.0  # transient, excluded
    rows = velocity_tracking(t, cmd, v)
    np.testing.assert_allclose([r["cmd"] for r in rows], [0.2, 0.5])
    np.testing.assert_allclose([r["v_mean"] for r in rows], [0.25, 0.4])
    np.testing.assert_allclose([r["rmse"] for r in rows], [0.05, 0.1], atol=1e-12)
