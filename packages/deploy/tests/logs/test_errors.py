# SPDX-License-Identifier: Apache-2.0
"""Bad input is refused (or warned about) with messages naming the problem and the fix."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gmloco.deploy.logs import (
    G1_JOINT_NAMES,
    G1LogWriter,
    JointOrderError,
    LogContractWarning,
    LogFormatError,
    LogWriterCfg,
    MissingTopicError,
    RunMetadata,
    UnitsError,
    read_log,
)


def _raw_mcap(path: Path, meta: dict[str, str], messages: list[tuple[str, str, int, bytes]]) -> Path:
    """Write an MCAP file by hand (to fake loggers that break the schema): (topic, encoding, t_ns, data)."""
    from mcap.writer import Writer

    with open(path, "wb") as f:
        w = Writer(f)
        w.start()
        w.add_metadata("gmloco.run", meta)
        channels: dict[str, int] = {}
        for topic, enc, t, data in messages:
            if topic not in channels:
                if enc == "protobuf":
                    from foxglove_schemas_protobuf.JointStates_pb2 import JointStates
                    from mcap_protobuf.schema import register_schema

                    sid = register_schema(w, JointStates)
                else:
                    sid = w.register_schema(topic, "jsonschema", b"{}")
                channels[topic] = w.register_channel(topic, enc, sid)
            w.add_message(channels[topic], log_time=t, data=data, publish_time=t)
        w.finish()
    return path


def _joint_states(names: list[str], q: float = 0.0) -> bytes:
    """Serialize a foxglove.JointStates with the given joint names."""
    from foxglove_schemas_protobuf.JointState_pb2 import JointState
    from foxglove_schemas_protobuf.JointStates_pb2 import JointStates

    return JointStates(joints=[JointState(name=n, position=q, velocity=0, effort=0) for n in names]).SerializeToString()


_IMU = json.dumps({"quaternion": [1, 0, 0, 0], "gyroscope": [0, 0, 0], "accelerometer": [0, 0, 9.81]}).encode()
_CMD = json.dumps({k: [0.0] * 29 for k in ("q", "dq", "kp", "kd", "tau")}).encode()


def _fake_log(path: Path, names: list[str], times: list[int] | None = None, cmd: bytes = _CMD) -> Path:
    """A minimal log whose JointStates carry ``names``."""
    times = times or [0, 5_000_000, 10_000_000]
    msgs = []
    for t in times:
        msgs += [("/lowstate/joint_states", "protobuf", t, _joint_states(names)), ("/lowstate/imu", "json", t, _IMU),
                 ("/lowcmd", "json", t, cmd)]  # fmt: skip
    return _raw_mcap(path, RunMetadata(controller="policy").to_record(), msgs)


def test_minimal_hand_written_log_reads(tmp_path: Path) -> None:
    """The fake-logger helper itself produces a valid log (so the failures below are due to the defect)."""
    log = read_log(_fake_log(tmp_path / "ok.mcap", list(G1_JOINT_NAMES)))
    assert log.signal("lowstate.q")[1].shape == (3, 29)


def test_missing_required_topic(tmp_path: Path, synthetic: Any, write_log: Any) -> None:
    """A log without /lowcmd is refused, naming the topic and what a log needs."""
    path = write_log(tmp_path / "nocmd.mcap", synthetic, skip=("/lowcmd",))
    with pytest.raises(MissingTopicError, match=r"required topic\(s\) \['/lowcmd'\].*needs /lowstate/joint_states"):
        read_log(path)


def test_missing_optional_channels_are_absent(tmp_path: Path, synthetic: Any, write_log: Any) -> None:
    """Optional channels (odometry, eta) may be missing: has() is False and alignment skips them."""
    path = write_log(tmp_path / "noopt.mcap", synthetic, skip=("/odometry", "/student/eta"))
    log = read_log(path)
    assert not log.has("odom.linear_velocity") and not log.has("student.eta")
    a = log.aligned()
    assert "odom.linear_velocity" not in a and "lowstate.q" in a
    with pytest.raises(KeyError, match=r"has no 'student\.eta'"):
        log.signal("student.eta")


def test_wrong_joint_count_in_joint_states(tmp_path: Path) -> None:
    """JointStates with 23 joints (a 23-DoF G1 or a partial logger) is refused with the count and the fix."""
    with pytest.raises(JointOrderError, match=r"23 joints, expected the 29 joints.*missing \["):
        read_log(_fake_log(tmp_path / "j23.mcap", list(G1_JOINT_NAMES[:23])))


def test_wrong_joint_count_in_lowcmd(tmp_path: Path) -> None:
    """LowCmd arrays with 28 entries are refused, naming topic, field and message."""
    cmd = json.dumps({k: [0.0] * 28 for k in ("q", "dq", "kp", "kd", "tau")}).encode()
    with pytest.raises(JointOrderError, match=r"/lowcmd: field 'q' of message 0 has 28 joints"):
        read_log(_fake_log(tmp_path / "c28.mcap", list(G1_JOINT_NAMES), cmd=cmd))


def test_unknown_joint_names(tmp_path: Path) -> None:
    """Unitree SDK motor names instead of G1 joint names are refused, listing the unknown names."""
    names = list(G1_JOINT_NAMES)
    names[0] = "L_LEG_HIP_PITCH"
    with pytest.raises(
        JointOrderError, match=r"unknown names \['L_LEG_HIP_PITCH'\].*missing \['left_hip_pitch_joint'\]"
    ):
        read_log(_fake_log(tmp_path / "sdk.mcap", names))


def test_writer_rejects_wrong_shapes(tmp_path: Path) -> None:
    """The writer refuses arrays of the wrong length, naming the field."""
    with (
        G1LogWriter(tmp_path / "w.mcap", RunMetadata(controller="x")) as w,
        pytest.raises(ValueError, match=r"q: expected shape"),
    ):
        w.write_lowstate(
            0.0, np.zeros(28), np.zeros(29), np.zeros(29), np.array([1, 0, 0, 0]), np.zeros(3), np.zeros(3)
        )


def test_units_mismatch_is_refused(tmp_path: Path, synthetic: Any, write_log: Any) -> None:
    """A file declaring joint positions in degrees is refused with the field, both units and the fix."""
    meta = RunMetadata(controller="policy")
    meta.units["lowstate.q"] = "deg"
    path = write_log(tmp_path / "deg.mcap", synthetic, meta=meta)
    with pytest.raises(UnitsError, match=r"lowstate.q: file says 'deg', schema says 'rad'.*Convert to SI"):
        read_log(path)


def test_degrees_without_declaration_warn(tmp_path: Path, synthetic: Any, write_log: Any) -> None:
    """Joint positions logged in degrees but declared as radians trip the range check."""
    synthetic.q = np.degrees(synthetic.q) * 3
    with pytest.warns(LogContractWarning, match="outside the G1 joint ranges.*Degrees"):
        read_log(write_log(tmp_path / "degq.mcap", synthetic))


def test_accelerometer_in_g_warns(tmp_path: Path, synthetic: Any, write_log: Any) -> None:
    """An accelerometer logged in g (norm ~1) is flagged."""
    synthetic.acc = synthetic.acc / 9.81
    with pytest.warns(LogContractWarning, match=r"accelerometer norm 1\.00"):
        read_log(write_log(tmp_path / "g.mcap", synthetic))


def test_non_monotonic_timestamps_warn_and_sort(tmp_path: Path) -> None:
    """Timestamps that go backwards are reported with the position, then sorted."""
    path = _fake_log(tmp_path / "back.mcap", list(G1_JOINT_NAMES), times=[0, 10_000_000, 5_000_000, 15_000_000])
    with pytest.warns(
        LogContractWarning, match=r"/lowstate/joint_states: 1 timestamps go backwards \(first after message 1"
    ):
        log = read_log(path)
    np.testing.assert_allclose(log.signal("lowstate.q")[0], [0.0, 0.005, 0.010, 0.015])


def test_not_a_gmloco_log(tmp_path: Path) -> None:
    """An MCAP without run metadata is refused, pointing at the writer."""
    from mcap.writer import Writer

    path = tmp_path / "other.mcap"
    with open(path, "wb") as f:
        w = Writer(f)
        w.start()
        w.finish()
    with pytest.raises(LogFormatError, match=r"no 'gmloco.run' metadata record.*G1LogWriter"):
        read_log(path)


def test_declared_but_empty_required_topic(tmp_path: Path) -> None:
    """Channels declared up front but never written count as missing."""
    with G1LogWriter(tmp_path / "empty.mcap", RunMetadata(controller="x"), LogWriterCfg()):
        pass
    with pytest.raises(MissingTopicError, match="/lowstate/joint_states"):
        read_log(tmp_path / "empty.mcap")
