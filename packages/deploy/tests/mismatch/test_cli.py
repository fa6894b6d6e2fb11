# SPDX-License-Identifier: Apache-2.0
"""MCAP round trip through the logs package, and the CLI end to end on a tiny recording."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gmloco.deploy.mismatch.cli import main
from gmloco.deploy.mismatch.io import read_recording, write_recording
from gmloco.deploy.mismatch.pipeline import AnalysisCfg, analyze
from gmloco.deploy.mismatch.recording import Recording


def test_mcap_roundtrip(delay_rec: object, tmp_path: Path) -> None:
    """Writing with G1LogWriter and reading with read_log preserves the arrays on the 500 Hz grid."""
    path = write_recording(delay_rec, tmp_path / "real.mcap", controller="scripted_step")
    back = read_recording(path)
    assert back.n == delay_rec.n
    np.testing.assert_allclose(back.q, delay_rec.q, atol=1e-6)
    np.testing.assert_allclose(back.q_cmd, delay_rec.q_cmd, atol=1e-6)
    np.testing.assert_allclose(back.imu_acc, delay_rec.imu_acc, atol=1e-6)
    assert back.valid_mask().all()


def test_cli_writes_report(delay_rec: object, tmp_path: Path) -> None:
    """``gmloco-mismatch --real`` writes report.json (schema, verdict), report.md and the config patch."""
    path = write_recording(delay_rec, tmp_path / "real.mcap")
    out = tmp_path / "out"
    assert (
        main(["--real", str(path), "--out", str(out), "--effects", "actuator.delay,actuator.gain_scale", "--no-plots"])
        == 0
    )
    rep = json.loads((out / "report.json").read_text())
    assert rep["schema"] == "gmloco.mismatch_report/1"
    assert rep["verdict"] == "explained" and rep["winner"] == "actuator.delay"
    assert "actuator.delay" in json.loads((out / "config_patch.json").read_text())
    assert "Verdict" in (out / "report.md").read_text()


def test_cli_refuses_a_material_on_the_plane_and_a_zero_horizon(delay_rec: object, tmp_path: Path) -> None:
    """``--ground plane:dry_sand`` and ``--horizon 0`` stop with exit code 2 and no report."""
    path = write_recording(delay_rec, tmp_path / "real.mcap")
    for extra in (["--ground", "plane:dry_sand"], ["--horizon", "0"]):
        out = tmp_path / extra[0].strip("-")
        assert main(["--real", str(path), "--out", str(out), "--no-plots", *extra]) == 2
        assert not (out / "report.json").exists()


def test_cli_refuses_an_unknown_effect_id(
    delay_rec: Recording, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--effects actuator.dleay`` stops with exit code 2, names the id and its closest match, writes no report."""
    path = write_recording(delay_rec, tmp_path / "real.mcap")
    out = tmp_path / "out"
    assert main(["--real", str(path), "--out", str(out), "--no-plots", "--effects", "actuator.dleay"]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert "'actuator.dleay' (did you mean 'actuator.delay'?)" in err
    assert not (out / "report.json").exists()


def test_analyze_refuses_an_unknown_effect_id(null_rec: Recording) -> None:
    """``analyze`` raises instead of screening nothing and answering ``unexplained``."""
    cfg = AnalysisCfg()
    cfg.attribution.effects = ("actuator.delay", "joint.frction")
    with pytest.raises(ValueError, match=r"joint\.frction"):
        analyze(null_rec, cfg)
