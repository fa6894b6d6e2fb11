# SPDX-License-Identifier: Apache-2.0
"""The benchmark sweep end to end on a fast subset: one short episode, a three-effect screen."""

from __future__ import annotations

import json
from pathlib import Path

from gmloco.deploy.mismatch.benchmark.sweep import main


def test_sweep_subset_writes_rows_summary_manifest_and_a_separate_key(tmp_path: Path) -> None:
    """A 3 s hidden gyro bias is named and fitted; the truth key is written under keys/, apart from the rows."""
    main(
        [
            "--out",
            str(tmp_path),
            "--only",
            "imu.gyro_bias-mid-0",
            "--nulls",
            "0",
            "--duration",
            "3",
            "--workers",
            "1",
            "--effects",
            "imu.gyro_bias,joint.armature,actuator.delay",
        ]
    )
    row = json.loads((tmp_path / "rows" / "imu.gyro_bias-mid-0.json").read_text())
    assert row["verdict"] == "explained" and row["winner"] == "imu.gyro_bias", row
    fit = row["fit"]
    # truth (0.03, -0.02, 0.015) rad/s; the gyro-vs-attitude-rate channel pins it to a few mrad/s
    for lab, truth in (("bias[x]", 0.03), ("bias[y]", -0.02), ("bias[z]", 0.015)):
        assert abs(fit[lab][0] - truth) < 0.004
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["overall"]["top1_mid_macro"] == 1.0
    manifest = json.loads((tmp_path / "manifest.json").read_text())
    inv = manifest["invocations"][-1]
    assert inv["episodes"] == ["imu.gyro_bias-mid-0"] and "commit" in inv["git"]
    assert (tmp_path / "keys" / "imu.gyro_bias-mid-0.json").exists()
