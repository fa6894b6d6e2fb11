# SPDX-License-Identifier: Apache-2.0
"""MCAP round trip of a recording: held commands keep their sample (no spurious one-sample delay)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from gmloco.deploy.mismatch.io import read_recording, write_recording


def test_roundtrip_keeps_step_commands_on_their_sample(null_rec: object, tmp_path: Path) -> None:
    """Commands that jump every 10 samples (a 50 Hz policy at 500 Hz) come back on the same samples.

    The clock starts at 1000 s, as a robot's does: the reader's float grid then falls nanoseconds before the
    message stamps, which once put every held command one sample late.
    """
    rec = null_rec
    steps = np.repeat(np.random.default_rng(0).normal(0.0, 0.3, (rec.n // 10 + 1, 29)), 10, axis=0)[: rec.n]
    rec = dataclasses.replace(rec, q_cmd=rec.q_cmd + steps, t=1000.0 + np.arange(rec.n) * 0.002)
    back = read_recording(write_recording(rec, tmp_path / "r.mcap"))
    assert back.n == rec.n
    rec = dataclasses.replace(rec, t=rec.t - rec.t[0])
    # float64 -> MCAP -> float64 of the values themselves; a one-sample shift would give ~0.3 rad errors
    np.testing.assert_allclose(back.q_cmd, rec.q_cmd, atol=1e-6)
    np.testing.assert_allclose(back.q, rec.q, atol=1e-6)


def test_a_derived_accelerometer_is_read_as_such_and_left_out(null_rec: object, tmp_path: Path) -> None:
    """A log that declares its accelerometer derived (or an MPM-evaluation log): a contract warning, acc weight 0."""
    from dataclasses import replace

    from gmloco.deploy.logs.reader import read_log
    from gmloco.deploy.mismatch.contract import check_recording
    from gmloco.deploy.mismatch.io import _derived_signals
    from gmloco.deploy.mismatch.problem import Problem
    from gmloco.deploy.mismatch.replay import Replayer

    md = read_log(write_recording(null_rec, tmp_path / "n.mcap")).metadata
    assert _derived_signals(md) == ""
    assert _derived_signals(replace(md, contact_model="mpm")) == "imu.accelerometer"  # older MPM logs
    assert _derived_signals(replace(md, extra={"derived_signals": "imu.accelerometer"})) == "imu.accelerometer"
    rec = replace(null_rec, meta={**null_rec.meta, "derived_signals": "imu.accelerometer"})
    assert rec.acc_derived and not null_rec.acc_derived
    assert any("derived" in i.message for i in check_recording(rec))
    w = Problem(Replayer(rec)).weight
    assert np.all(w[90:93] == 0.0) and np.all(w[87:90] > 0.0)  # acc out, gyro kept
    assert np.all(Problem(Replayer(null_rec)).weight[90:93] > 0.0)
