# SPDX-License-Identifier: Apache-2.0
"""Simulator-side recorder: a short MuJoCo C run produces a schema-conforming, honestly labelled log."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gmloco.deploy.logs import read_log


def test_scripted_recording_roundtrip_and_physics(tmp_path: Path) -> None:
    """Standing phase: the ground carries the robot's weight (sum of vertical foot forces = m g).

    The gantry carries no weight (weight_fraction = 0), so in quasi-static standing
    sum F_z = m g = 33.34 kg * 9.81 m/s^2 = 327 N; 5 % covers the settling sway.
    """
    pytest.importorskip("mujoco")
    pytest.importorskip("mjlab", reason="the G1 MJCF ships with mjlab")
    from gmloco.deploy.logs.analysis import g1_model
    from gmloco.deploy.logs.sim import CommandSegment, ScriptedRunCfg, record_scripted_run

    path = record_scripted_run(tmp_path / "run.mcap", ScriptedRunCfg(duration=1.5, commands=(CommandSegment(0, 0.2),)))
    log = read_log(path)
    assert log.metadata.controller == "scripted_stepping" and log.metadata.policy == "none"
    assert log.metadata.support.startswith("virtual_gantry") and log.metadata.material == "rigid"
    t, f = log.signal("sim.force")
    standing = (t > 0.5) & (t < 0.95)
    weight = g1_model()["mass"] * 9.81
    np.testing.assert_allclose(f[standing, :, 2].sum(1).mean(), weight, rtol=0.05)
    _, acc = log.signal("imu.accelerometer")
    np.testing.assert_allclose(np.linalg.norm(acc[standing], axis=1).mean(), 9.81, rtol=0.05)
    _, kp = log.signal("lowcmd.kp")
    assert (kp > 0).all()
    assert log.run_end["end_reason"] == "completed"
