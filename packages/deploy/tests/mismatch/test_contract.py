# SPDX-License-Identifier: Apache-2.0
"""Data-contract checks: wrong joint maps and bad units are contract errors, never physics."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from gmloco.deploy.mismatch.contract import ContractCfg, ContractError, JointMapError, _quat_order, check_recording
from gmloco.deploy.mismatch.frames import quat_conj, quat_from_roll_pitch, quat_mul, quat_to_mat
from gmloco.deploy.mismatch.pipeline import AnalysisCfg, analyze
from gmloco.deploy.mismatch.recording import Recording

SAMPLE_LOGS = Path(__file__).resolve().parents[2] / "data" / "sample_logs"
"""The committed sample recordings."""


def test_clean_recording_passes(null_rec: Recording) -> None:
    """A generated recording has no contract errors."""
    assert not [i for i in check_recording(null_rec) if i.severity == "error"]


def test_swapped_state_columns_are_a_joint_map_error(null_rec: Recording) -> None:
    """Left/right hip-pitch and knee state columns swapped (commands not) -> JointMapError naming the joints."""
    perm = np.arange(29)
    perm[[0, 6]] = perm[[6, 0]]
    perm[[3, 9]] = perm[[9, 3]]
    bad = dataclasses.replace(null_rec, q=null_rec.q[:, perm], dq=null_rec.dq[:, perm])
    with pytest.raises(JointMapError, match="knee"):
        check_recording(bad)


def test_joint_map_error_reported_not_attributed(null_rec: Recording) -> None:
    """The pipeline turns a wrong joint map into an ``invalid_input`` report with a joint_map issue."""
    perm = np.arange(29)
    perm[[3, 9]] = perm[[9, 3]]
    bad = dataclasses.replace(null_rec, q=null_rec.q[:, perm], dq=null_rec.dq[:, perm])
    rep = analyze(bad, AnalysisCfg(mirror_check=False)).report
    assert rep["verdict"] == "invalid_input"
    assert any(c["check"] == "joint_map" for c in rep["contract"])
    assert rep["hypotheses"] == []


def test_degrees_and_g_units_rejected(null_rec: Recording) -> None:
    """Positions in degrees and accelerometer in g are unit errors."""
    with pytest.raises(ContractError, match="degrees"):
        check_recording(dataclasses.replace(null_rec, q=np.degrees(null_rec.q)))
    with pytest.raises(ContractError, match="g units"):
        check_recording(dataclasses.replace(null_rec, imu_acc=null_rec.imu_acc / 9.81))


def test_too_short_recording_lists_untested_effects(null_rec: Recording) -> None:
    """A 1 s recording is rejected and every effect is listed as untested with a reason and a remedy."""
    rep = analyze(null_rec.slice(0, 500)).report
    assert rep["verdict"] == "invalid_input"
    assert len(rep["untested"]) >= 10
    assert all(u["reason"] and u["needs"] for u in rep["untested"])


def test_low_gain_policy_with_far_targets_passes(null_rec: Recording) -> None:
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


def test_tau_est_from_the_previous_command_passes(null_rec: Recording) -> None:
    """tau_est made by the command of the sample before (a 50 Hz policy log) is no joint-map error.

    The 50 Hz simulator recordings log the state of step i with the target sent for [t_i, t_i+1), while the torque
    at that state comes from the previous target: tau_est_i = kp (q*_{i-1} - q_i) - kd dq_i. Targets that jump
    by ~0.3 rad per step (an RL policy's wrists) make the same-sample motor law misfit the labelled column.
    """
    arrays = {f.name: getattr(null_rec, f.name) for f in dataclasses.fields(null_rec)}
    every10 = {k: v[::10] for k, v in arrays.items() if isinstance(v, np.ndarray)}
    rec = dataclasses.replace(null_rec, **every10)  # 500 Hz -> 50 Hz, a policy-rate recording
    rng = np.random.default_rng(1)
    q_cmd = rec.q + 0.3 * rng.standard_normal(rec.q.shape)
    tau = np.zeros_like(rec.q)
    tau[1:] = rec.kp[1:] * (q_cmd[:-1] - rec.q[1:]) - rec.kd[1:] * rec.dq[1:]
    lagged = dataclasses.replace(rec, q_cmd=q_cmd, tau_est=tau)
    assert not [i for i in check_recording(lagged) if i.check == "joint_map"]
    perm = np.arange(29)
    perm[[3, 9]] = perm[[9, 3]]  # a real swap of the knee state columns is still caught
    with pytest.raises(JointMapError, match="knee"):
        check_recording(dataclasses.replace(lagged, q=rec.q[:, perm], dq=rec.dq[:, perm]))


def test_committed_policy_recording_passes_the_joint_map() -> None:
    """The committed 50 Hz sample recording of the PPO policy on dry sand has a right joint map."""
    from gmloco.deploy.mismatch.io import read_recording

    path = SAMPLE_LOGS / "g1_ppo_rft3d_it542_unvalidated_dry_sand_v1.mcap"
    assert not [i for i in check_recording(read_recording(path)) if i.check == "joint_map"]


def _turned(rec: Recording, start_deg: float, sweep_deg: float) -> Recording:
    """``rec`` turned about the world vertical at a constant rate from ``start_deg`` through ``sweep_deg``.

    The heading rotation multiplies the quaternion on the left; the gyro gains the yaw rate seen in the IMU frame
    and the accelerometer (specific force in the IMU frame) is unchanged: a valid, correctly ordered recording.
    """
    dur = rec.t[-1] - rec.t[0]
    psi = np.radians(start_deg + sweep_deg * (rec.t - rec.t[0]) / dur)
    q_yaw = np.stack([np.cos(psi / 2), 0 * psi, 0 * psi, np.sin(psi / 2)], axis=-1)
    rate = np.einsum("nji,j->ni", quat_to_mat(rec.imu_quat), [0.0, 0.0, np.radians(sweep_deg) / dur])
    return dataclasses.replace(rec, imu_quat=quat_mul(q_yaw, rec.imu_quat), imu_gyro=rec.imu_gyro + rate)


def _xyzw(rec: Recording) -> Recording:
    """``rec`` with its quaternion stored (x, y, z, w) in the (w, x, y, z) columns."""
    return dataclasses.replace(rec, imu_quat=rec.imu_quat[:, [1, 2, 3, 0]])


@pytest.mark.parametrize(("start_deg", "sweep_deg"), [(60.0, 160.0), (150.0, 60.0), (0.0, 360.0), (-30.0, -300.0)])
def test_turning_recording_passes_quaternion_order(null_rec: Recording, start_deg: float, sweep_deg: float) -> None:
    """A robot whose heading sits past 120 deg (median |w| < 0.5) is not a swapped quaternion (issue #8)."""
    turned = _turned(null_rec, start_deg, sweep_deg)
    assert not [i for i in check_recording(turned, raise_on_error=False) if i.severity == "error"]


def test_turning_recording_with_median_w_under_half(null_rec: Recording) -> None:
    """The case that used to be rejected: heading beyond 120 deg for most of the recording."""
    turned = _turned(null_rec, 150.0, 60.0)
    assert np.median(np.abs(turned.imu_quat[:, 0])) < 0.5 < np.median(np.abs(turned.imu_quat[:, 3]))
    assert not [i for i in check_recording(turned, raise_on_error=False) if i.check == "units"]


@pytest.mark.parametrize(("start_deg", "sweep_deg"), [(0.0, 0.0), (60.0, 160.0), (150.0, 60.0), (0.0, 360.0)])
def test_xyzw_quaternion_rejected(null_rec: Recording, start_deg: float, sweep_deg: float) -> None:
    """A quaternion stored (x, y, z, w) is a units error at any heading, turning or not."""
    rec = _turned(null_rec, start_deg, sweep_deg) if sweep_deg else null_rec
    with pytest.raises(ContractError, match=r"\(x, y, z, w\)") as err:
        check_recording(_xyzw(rec))
    issue = next(i for i in err.value.issues if "(x, y, z, w)" in i.message)
    assert set(issue.detail["gyro_misfit_rad_s"]) == {"wxyz", "xyzw"}


def _synthetic_imu(yaw_deg: np.ndarray, dt: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quaternion, gyro and accelerometer of a body turning through ``yaw_deg`` with small roll/pitch sway.

    Sway of 2-3 deg at about 1 Hz, gyro from the quaternion's body rate (central differences) with noise and a
    bias, accelerometer = gravity in the body frame with noise (no other motion).
    """
    rng = np.random.default_rng(seed)
    t = np.arange(len(yaw_deg)) * dt
    roll, pitch = np.radians(3.0) * np.sin(2 * np.pi * 0.9 * t), np.radians(2.0) * np.sin(2 * np.pi * 1.1 * t + 1)
    psi = np.radians(yaw_deg)
    q_yaw = np.stack([np.cos(psi / 2), 0 * psi, 0 * psi, np.sin(psi / 2)], axis=-1)
    quat = quat_mul(q_yaw, np.stack([quat_from_roll_pitch(r, p) for r, p in zip(roll, pitch, strict=True)]))
    dq = np.gradient(quat, dt, axis=0)
    gyro = 2.0 * quat_mul(quat_conj(quat), dq)[:, 1:] + [0.01, -0.02, 0.005] + rng.normal(0, 0.004, (len(t), 3))
    acc = quat_to_mat(quat)[:, 2, :] * 9.81 + rng.normal(0, 0.05, (len(t), 3))
    return quat, gyro, acc


@pytest.mark.parametrize("sweep_deg", [0.0, 150.0, 240.0, 360.0])
def test_quat_order_is_heading_independent(sweep_deg: float) -> None:
    """Synthetic slow turns (10 s, 500 Hz, starting at 100 deg): the right order passes, (x, y, z, w) is caught."""
    dt = 0.002
    yaw = 100.0 + sweep_deg * np.linspace(0.0, 1.0, 5000)
    quat, gyro, acc = _synthetic_imu(yaw, dt)
    assert not _quat_order(quat, gyro, acc, dt, ContractCfg())[0]
    assert _quat_order(quat[:, [1, 2, 3, 0]], gyro, acc, dt, ContractCfg())[0]


def test_quat_order_uninformative_recording_passes() -> None:
    """Standing still facing 180 deg: both readings look upright and the gyro is idle, so nothing is rejected."""
    rng = np.random.default_rng(1)
    quat = quat_mul(np.array([0.0, 0.0, 0.0, 1.0]), quat_from_roll_pitch(0.01, -0.01)) * np.ones((2000, 1))
    gyro = rng.normal(0, 0.004, (2000, 3))
    acc = quat_to_mat(quat)[:, 2, :] * 9.81 + rng.normal(0, 0.05, (2000, 3))
    assert np.median(np.abs(quat[:, 0])) < 0.5 < np.median(np.abs(quat[:, 3]))  # what the old check rejected
    assert not _quat_order(quat, gyro, acc, 0.002, ContractCfg())[0]
