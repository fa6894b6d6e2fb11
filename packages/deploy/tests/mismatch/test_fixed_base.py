# SPDX-License-Identifier: Apache-2.0
"""Fixed-base (gantry) recordings: welded replay, motion phases, support contract, CLI exit codes."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gmloco.deploy.mismatch.benchmark.chirp import ChirpCfg
from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
from gmloco.deploy.mismatch.benchmark.truth import TruthEffect
from gmloco.deploy.mismatch.cli import main
from gmloco.deploy.mismatch.contract import ContractError, check_recording
from gmloco.deploy.mismatch.io import read_recording, write_recording
from gmloco.deploy.mismatch.pipeline import AnalysisCfg, analyze
from gmloco.deploy.mismatch.recording import Recording, support_from_label
from gmloco.deploy.mismatch.replay import Replayer
from gmloco.deploy.mismatch.segmentation import motion_phases

DURATION = 3.0


def _chirp(effect: TruthEffect, seed: int = 5) -> Recording:
    """A 3 s gantry chirp recording with one hidden effect (nuisances and noise on)."""
    rec, _ = generate(
        EpisodeCfg(effect=effect, duration=DURATION, seed=seed, support="gantry", chirp=ChirpCfg(duration=DURATION))
    )
    return rec


@pytest.fixture(scope="module")
def chirp_null() -> Recording:
    """Gantry chirp, no hidden effect."""
    return _chirp(TruthEffect())


@pytest.fixture(scope="module")
def chirp_delay() -> Recording:
    """Gantry chirp with a hidden 8 ms command delay (the benchmark's mid strength)."""
    return _chirp(TruthEffect("actuator.delay", {"delay": [0.008]}))


def test_support_labels() -> None:
    """Metadata labels map to supports; the simulator's virtual gantry is a free base; a typo is refused."""
    assert support_from_label("none") == "free"
    assert support_from_label("gantry") == "gantry"
    assert support_from_label("fixed") == "fixed"
    assert support_from_label("virtual_gantry(roll_pitch_stiffness=400.0 N*m/rad)") == "free"
    with pytest.raises(ValueError, match="support"):
        support_from_label("gantri")


def test_welded_replay_senses_a_pelvis_at_rest(chirp_null: Recording) -> None:
    """The welded replay's IMU is that of a still pelvis: gyro 0, specific force = gravity (logged ~9.81 on z).

    The truth pelvis is tilted by at most 2 degrees per axis, so the logged z force is >= 9.81 cos(2 deg)^2.
    """
    rp = Replayer(chirp_null)
    starts = rp.segment_starts()[:10]
    sim = rp.simulate({}, starts)
    np.testing.assert_allclose(sim[..., 87:90], 0.0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(sim[..., 90:93], axis=-1), 9.81, rtol=1e-9)
    # the welded orientation is the logged one: simulated and logged specific force agree to the noise
    np.testing.assert_allclose(sim[..., 90:93].mean((0, 1)), rp.measured(starts)[..., 90:93].mean((0, 1)), atol=0.02)


def test_fixed_null_is_no_mismatch(chirp_null: Recording) -> None:
    """A gantry chirp without a hidden effect is ``no_mismatch``; cells carry motion labels, not foot phases."""
    rep = analyze(chirp_null, AnalysisCfg(mirror_check=False)).report
    assert rep["verdict"] == "no_mismatch", rep["mismatch"]
    assert rep["recording"]["support"] == "gantry" and rep["recording"]["base_state"] == "welded"
    phases = {c["phase"] for c in rep["mismatch"]["cells"]}
    assert phases <= {"hold", "low_freq", "high_freq"}


def test_fixed_delay_is_explained(chirp_delay: Recording) -> None:
    """A hidden 8 ms delay on a gantry is explained by ``actuator.delay``, fitted within 15 % (ZOH adds ~1 ms)."""
    rep = analyze(chirp_delay, AnalysisCfg(mirror_check=False)).report
    assert rep["verdict"] == "explained" and rep["winner"] == "actuator.delay"
    h = next(h for h in rep["hypotheses"] if h["id"] == "actuator.delay")
    assert abs(h["params"]["delay"]["value"] - 0.008) < 0.15 * 0.008
    cells = rep["mismatch"]["cells"]
    assert cells and cells[0]["phase"] in ("low_freq", "high_freq")


def test_motion_phases_split_a_chirp() -> None:
    """A 1 Hz then 4 Hz sine is labelled low then high frequency; a constant command holds (split at 2 Hz)."""
    dt = 0.002
    t = np.arange(0, 4, dt)
    q = np.where(t < 2, 0.1 * np.sin(2 * np.pi * 1.0 * t), 0.1 * np.sin(2 * np.pi * 4.0 * t))
    codes = motion_phases(np.stack([q, np.zeros_like(q)], axis=1), dt)
    assert np.all(codes[250:750, 0] == 1) and np.all(codes[1250:1750, 0] == 2)
    assert np.all(codes[:, 1] == 0)


def test_still_imu_replayed_free_is_a_contract_error(chirp_null: Recording, null_rec: Recording) -> None:
    """A gantry recording labelled free is refused with a support error; free and held stepping are checked too."""
    with pytest.raises(ContractError, match="support is 'free'"):
        check_recording(replace(chirp_null, support="free"))
    assert not [i for i in check_recording(null_rec) if i.check == "support"]
    with pytest.raises(ContractError, match="support is 'gantry'"):
        check_recording(replace(null_rec, support="gantry"))


def test_cli_fixed_and_mislabelled(chirp_null: Recording, tmp_path: Path) -> None:
    """The CLI reads ``support`` from the MCAP (exit 0, ``no_mismatch``); ``--support free`` exits 2.

    The mislabelled run's report is ``invalid_input`` and its support issue names the support.
    """
    path = write_recording(chirp_null, tmp_path / "gantry.mcap", controller="scripted_chirp")
    assert read_recording(path).support == "gantry"
    out = tmp_path / "ok"
    assert main(["--real", str(path), "--out", str(out), "--no-plots"]) == 0
    assert json.loads((out / "report.json").read_text())["verdict"] == "no_mismatch"
    bad = tmp_path / "free"
    assert main(["--real", str(path), "--out", str(bad), "--no-plots", "--support", "free"]) == 2
    rep = json.loads((bad / "report.json").read_text())
    assert rep["verdict"] == "invalid_input"
    assert any(c["check"] == "support" and "support is 'free'" in c["message"] for c in rep["contract"])


def test_sample_logs_stay_free() -> None:
    """The shipped sample logs (``none``, ``virtual_gantry(...)``) read as free bases and pass the support check.

    Their legs shake the pelvis: IMU variation 0.35-0.59 m/s^2 per rad/s^2 of joint acceleration.
    """
    logs = sorted((Path(__file__).parents[2] / "data" / "sample_logs").glob("*.mcap"))
    assert len(logs) >= 4
    for path in logs:
        rec = read_recording(path)
        assert rec.support == "free" and not rec.fixed_base
        assert not [i for i in check_recording(rec, raise_on_error=False) if i.check == "support"], path.name


def test_welded_pose_follows_logged_odometry() -> None:
    """With ``/odometry`` logged, the welded pelvis takes the logged orientation (the truth's tilted gantry pose)."""
    rec, _ = generate(EpisodeCfg(duration=2.5, seed=7, support="fixed", odometry=True, chirp=ChirpCfg(duration=2.5)))
    assert rec.base_quat is not None
    rp = Replayer(rec)
    starts = rp.segment_starts()[:5]
    base = rp.base({}, starts)
    assert base.source == "welded"
    np.testing.assert_allclose(base.quat, rec.base_quat[starts], atol=1e-12)
    assert not np.allclose(base.quat[0], [1.0, 0.0, 0.0, 0.0], atol=1e-4)  # the nuisance tilt is there
