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
