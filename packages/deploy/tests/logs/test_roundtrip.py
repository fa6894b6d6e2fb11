# SPDX-License-Identifier: Apache-2.0
"""Write -> read round trips: every channel comes back exactly, in canonical joint order."""

from __future__ import annotations

import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gmloco.deploy.logs import G1_JOINT_NAMES, read_log


@pytest.fixture(autouse=True)
def _no_warnings() -> None:
    """An intact file must read without any warning."""
    warnings.simplefilter("error")


def test_roundtrip_every_channel_exact(synthetic_log: Path, synthetic: Any) -> None:
    """Every signal of every topic reads back bit-exact (JSON and protobuf keep float64)."""
    s = synthetic
    log = read_log(synthetic_log)
    exact = {
        "lowstate.q": s.q, "lowstate.dq": s.dq, "lowstate.ddq": s.ddq, "lowstate.tau_est": s.tau,
        "imu.quaternion": s.quat, "imu.gyroscope": s.gyro, "imu.accelerometer": s.acc, "imu.rpy": s.rpy,
        "lowcmd.q": s.cmd_q, "lowcmd.kp": s.kp, "lowcmd.kd": s.kd,
        "motor.temperature": s.temp, "motor.vol": s.vol,
        "odom.position": s.pos, "odom.orientation": s.quat, "odom.linear_velocity": s.vel,
        "odom.angular_velocity": s.gyro, "sim.in_contact": s.contact, "sim.force": s.force,
        "command.lin_vel_x": s.vx, "policy.observation": s.obs, "policy.action": s.action, "student.eta": s.eta,
    }  # fmt: skip
    for name, expected in exact.items():
        t, v = log.signal(name)
        np.testing.assert_array_equal(v, expected, err_msg=name)
    t, _ = log.signal("lowstate.q")
    np.testing.assert_allclose(t, s.t, atol=1e-9)  # integer ns on disk: 1 ns resolution
    np.testing.assert_array_equal(log.channels["/lowstate/joint_states"].sequence, 1000 + np.arange(len(s.t)))


def test_roundtrip_metadata_and_channel_metadata(synthetic_log: Path) -> None:
    """Run metadata, eta names and observation terms survive; /log events are returned."""
    log = read_log(synthetic_log)
    m = log.metadata
    assert (m.controller, m.policy, m.material) == ("policy", "test.onnx", "sand_loose")
    assert json.loads(log.channels["/student/eta"].metadata["names"]) == ["stiffness", "friction"]
    assert json.loads(log.channels["/policy/observation"].metadata["terms"])[0] == ["base_ang_vel", 3]
    assert log.events() == [(pytest.approx(0.5), 2, "stage S2: stepping in place")]
    assert log.run_end is not None and log.run_end["end_reason"] == "completed"
    assert log.damage == []


def test_joint_order_mapping(tmp_path: Path, synthetic: Any, write_log: Any) -> None:
    """A file logged in another joint order reads back in canonical order (JointStates and JSON arrays)."""
    order = tuple(reversed(G1_JOINT_NAMES))
    path = write_log(tmp_path / "reversed.mcap", synthetic, joint_order=order)
    log = read_log(path)
    np.testing.assert_array_equal(log.signal("lowstate.q")[1], synthetic.q)
    np.testing.assert_array_equal(log.signal("lowcmd.q")[1], synthetic.cmd_q)
    np.testing.assert_array_equal(log.signal("motor.temperature")[1], synthetic.temp)
    np.testing.assert_array_equal(log.signal("lowstate.tau_est", joint="left_knee_joint")[1], synthetic.tau[:, 3])


def test_nan_roundtrip(tmp_path: Path, synthetic: Any, write_log: Any) -> None:
    """Non-finite values are written as JSON null and read back as NaN."""
    synthetic.cmd_q[5, 3] = np.nan
    log = read_log(write_log(tmp_path / "nan.mcap", synthetic))
    v = log.signal("lowcmd.q")[1]
    assert np.isnan(v[5, 3])
    np.testing.assert_array_equal(np.isnan(v).sum(), 1)


def test_writer_refuses_to_overwrite(synthetic_log: Path, synthetic: Any, write_log: Any) -> None:
    """An existing file (e.g. an input log) is never overwritten by default."""
    with pytest.raises(FileExistsError, match="refusing to overwrite"):
        write_log(synthetic_log, synthetic)
