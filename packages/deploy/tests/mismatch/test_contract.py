# SPDX-License-Identifier: Apache-2.0
"""Data-contract checks: wrong joint maps and bad units are contract errors, never physics."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gmloco.deploy.mismatch.contract import ContractError, JointMapError, check_recording
from gmloco.deploy.mismatch.pipeline import AnalysisCfg, analyze


def test_clean_recording_passes(null_rec: object) -> None:
    """A generated recording has no contract errors."""
    assert not [i for i in check_recording(null_rec) if i.severity == "error"]


def test_swapped_state_columns_are_a_joint_map_error(null_rec: object) -> None:
    """Left/right hip-pitch and knee state columns swapped (commands not) -> JointMapError naming the joints."""
    perm = np.arange(29)
    perm[[0, 6]] = perm[[6, 0]]
    perm[[3, 9]] = perm[[9, 3]]
    bad = dataclasses.replace(null_rec, q=null_rec.q[:, perm], dq=null_rec.dq[:, perm])
    with pytest.raises(JointMapError, match="knee"):
        check_recording(bad)


def test_joint_map_error_reported_not_attributed(null_rec: object) -> None:
    """The pipeline turns a wrong joint map into an ``invalid_input`` report with a joint_map issue."""
    perm = np.arange(29)
    perm[[3, 9]] = perm[[9, 3]]
    bad = dataclasses.replace(null_rec, q=null_rec.q[:, perm], dq=null_rec.dq[:, perm])
    rep = analyze(bad, AnalysisCfg(mirror_check=False)).report
    assert rep["verdict"] == "invalid_input"
    assert any(c["check"] == "joint_map" for c in rep["contract"])
    assert rep["hypotheses"] == []


def test_degrees_and_g_units_rejected(null_rec: object) -> None:
    """Positions in degrees and accelerometer in g are unit errors."""
    with pytest.raises(ContractError, match="degrees"):
        check_recording(dataclasses.replace(null_rec, q=np.degrees(null_rec.q)))
    with pytest.raises(ContractError, match="g units"):
        check_recording(dataclasses.replace(null_rec, imu_acc=null_rec.imu_acc / 9.81))


def test_too_short_recording_lists_untested_effects(null_rec: object) -> None:
    """A 1 s recording is rejected and every effect is listed as untested with a reason and a remedy."""
    rep = analyze(null_rec.slice(0, 500)).report
    assert rep["verdict"] == "invalid_input"
    assert len(rep["untested"]) >= 10
    assert all(u["reason"] and u["needs"] for u in rep["untested"])


def test_low_gain_policy_with_far_targets_passes(null_rec: object) -> None:
    """Targets far from the measured positions (a low-gain RL policy) pass when tau_est follows the PD law.

    The commands are the measured positions plus a large, joint-mixing offset pattern (which the distance and
    correlation heuristics alone read as a swap); tau_est = kp (q* - q) - kd dq ties each command to its column.
    """
    rec = null_rec
    rng = np.random.default_rng(0)
    wobble = 0.6 * np.sin(np.outer(rec.t, rng.uniform(1.0, 3.0, 29)) + rng.uniform(0, 6, 29))
    q_cmd = rec.q + wobble[:, rng.permutation(29)]
    tau = rec.kp * (q_cmd - rec.q) - rec.kd * rec.dq
    far = dataclasses.replace(rec, q_cmd=q_cmd, tau_est=tau)
    assert not [i for i in check_recording(far) if i.check == "joint_map"]
    # the same commands with the state columns of the knees swapped are still caught
    perm = np.arange(29)
    perm[[3, 9]] = perm[[9, 3]]
    with pytest.raises(JointMapError):
        check_recording(dataclasses.replace(far, q=rec.q[:, perm], dq=rec.dq[:, perm]))
