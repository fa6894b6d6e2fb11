# SPDX-License-Identifier: Apache-2.0
"""Several recordings, one diagnosis: the stacked problem, the same-robot contract, per-recording excitation."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gmloco.deploy.mismatch.benchmark.chirp import ChirpCfg
from gmloco.deploy.mismatch.benchmark.controller import MotionCfg
from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
from gmloco.deploy.mismatch.benchmark.truth import TruthEffect
from gmloco.deploy.mismatch.cli import main
from gmloco.deploy.mismatch.io import write_recording
from gmloco.deploy.mismatch.multi import analyze_many
from gmloco.deploy.mismatch.pipeline import AnalysisCfg
from gmloco.deploy.mismatch.problem import Problem
from gmloco.deploy.mismatch.recording import Recording
from gmloco.deploy.mismatch.replay import Replayer
from gmloco.deploy.mismatch.stack import StackedProblem, check_same_robot

_ARMATURE = TruthEffect("joint.armature", {"scale": [1.5]})


def test_a_stack_of_one_is_its_problem(null_rec: Recording) -> None:
    """Per-segment floors and weights give the single problem's residual bit for bit, on any segment subset."""
    pb = Problem(Replayer(null_rec))
    st = StackedProblem([pb])
    mask = np.arange(len(pb.starts)) % 3 == 0
    params = {"actuator.delay": np.array([0.004])}
    np.testing.assert_array_equal(st.resid(params, mask), pb.resid(params, mask))
    np.testing.assert_array_equal(np.broadcast_to(st.scale(mask), (int(mask.sum()), 1, pb.sigma.size))[:, 0],
                                  np.broadcast_to(pb.scale(mask), (int(mask.sum()), pb.sigma.size)))  # fmt: skip


def test_recordings_of_another_joint_order_or_rate_are_refused(null_rec: Recording) -> None:
    """Another joint order, sample rate or robot keeps recordings out of one diagnosis, each named."""
    names = (null_rec.joint_names[1], null_rec.joint_names[0], *null_rec.joint_names[2:])
    swapped = replace(null_rec, joint_names=names)
    slow = replace(null_rec, t=null_rec.t * 2.0)
    other = replace(null_rec, meta={**null_rec.meta, "robot": "unitree_h1"})
    msgs = [i.message for i in check_same_robot([null_rec, swapped, slow, other])]
    assert len(msgs) == 3
    assert "recording 1" in msgs[0] and "joint order differs from column 0" in msgs[0]
    assert "recording 2" in msgs[1] and "sample rate 250 Hz vs 500 Hz" in msgs[1]
    assert "recording 3" in msgs[2] and "unitree_h1" in msgs[2]
    assert check_same_robot([null_rec, null_rec]) == []


def test_cli_refuses_recordings_at_two_rates_with_exit_2(tmp_path: Path) -> None:
    """``--real a --real b`` at 500 Hz and 250 Hz: invalid_input, exit 2, the report says why."""
    paths = []
    for rate in (500.0, 250.0):
        rec, _ = generate(EpisodeCfg(effect=TruthEffect(), duration=1.0, seed=2, rate_hz=rate))
        paths.append(write_recording(rec, tmp_path / f"r{int(rate)}.mcap", controller="scripted_step"))
    code = main(["--real", str(paths[0]), "--real", str(paths[1]), "--out", str(tmp_path / "rep"), "--no-plots"])
    assert code == 2
    rep = json.loads((tmp_path / "rep" / "report.json").read_text())
    assert rep["verdict"] == "invalid_input"
    assert any(c["check"] == "same_robot" and "sample rate" in c["message"] for c in rep["contract"])


@pytest.fixture(scope="module")
def chirp_and_step() -> list[Recording]:
    """A 3 s gantry chirp and 3 s of stepping on the plane, one robot with 1.5x armature (noise, nuisances)."""
    chirp, _ = generate(
        EpisodeCfg(effect=_ARMATURE, duration=3.0, seed=5, support="gantry", chirp=ChirpCfg(duration=3.0))
    )
    step, _ = generate(
        EpisodeCfg(effect=_ARMATURE, duration=3.0, seed=3, motion=MotionCfg(kind="step", stand_time=0.3))
    )
    return [chirp, step]


def test_a_chirp_and_a_stepping_recording_make_one_diagnosis(chirp_and_step: list[Recording]) -> None:
    """The stack finds the armature both recordings share, and says which recording excites which effect.

    The ground effect is excited by the stepping recording only: the held pelvis touches nothing.
    """
    cfg = AnalysisCfg()
    cfg.attribution.effects = ("joint.armature", "actuator.delay", "joint.viscous_damping", "terrain.stiffness_scale")
    rep = analyze_many(chirp_and_step, cfg).report
    assert rep["verdict"] == "explained" and rep["winner"] == "joint.armature"
    hyp = {h["id"]: h for h in rep["hypotheses"] if "rank" in h}
    np.testing.assert_allclose(hyp["joint.armature"]["params"]["scale"]["value"], 1.5, rtol=0.1)
    assert hyp["joint.armature"]["excited_by"] == [0, 1]
    assert hyp["terrain.stiffness_scale"]["excited_by"] == [1]
    recs = rep["recordings"]
    assert [r["support"] for r in recs] == ["gantry", "free"]
    assert [r["stage"] for r in recs] == ["chirp", "step"]
    assert "terrain.stiffness_scale" not in recs[0]["excites"] and "terrain.stiffness_scale" in recs[1]["excites"]
    assert rep["recording"]["segments"] == sum(r["segments"] for r in recs)
