# SPDX-License-Identifier: Apache-2.0
"""Write G1 runs to MCAP: numpy arrays in, schema-conforming MCAP out (simulator and hardware loggers)."""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from gmloco.deploy.g1 import G1_FEET, G1_NUM_JOINTS
from gmloco.deploy.logs.metadata import RunMetadata
from gmloco.deploy.logs.schema import (
    JOINT_DIM,
    METADATA_RUN,
    METADATA_RUN_END,
    TOPIC_COMMAND,
    TOPIC_ETA,
    TOPIC_IMU,
    TOPIC_JOINT_STATES,
    TOPIC_LOG,
    TOPIC_LOWCMD,
    TOPIC_MOTOR_AUX,
    TOPIC_ODOMETRY,
    TOPIC_POLICY_ACTION,
    TOPIC_POLICY_OBS,
    TOPIC_SIM_CONTACT,
    TOPIC_TF,
    TOPICS,
    json_schema,
)

__all__ = ["G1LogWriter", "LogWriterCfg"]

_REQUIRED = tuple(t for t, s in TOPICS.items() if s.required)


@dataclass
class LogWriterCfg:
    """Settings of :class:`G1LogWriter`."""

    chunk_size: int = 128 * 1024
    """Uncompressed chunk size [bytes]; a damaged chunk loses at most this much data."""
    compression: Literal["zstd", "lz4", "none"] = "zstd"
    """Chunk compression."""
    start_time_ns: int = 0
    """Added to every ``t`` [ns]; set to the Unix time of the first sample on hardware, 0 for reproducible sim files."""
    topics: tuple[str, ...] = _REQUIRED
    """Topics declared up front (their channel ids are also stored in the run metadata, so messages
    stay decodable when the chunk that declared the channel is damaged). Others are declared on first write."""
    overwrite: bool = False
    """Replace an existing file at the output path (refused by default, so inputs are never overwritten)."""


def _ns(t: float) -> int:
    """Convert seconds to integer nanoseconds."""
    return round(t * 1e9)


def _jsonable(a: Any) -> Any:
    """Convert an array to nested lists; non-finite numbers become ``null`` (JSON has no NaN)."""
    arr = np.asarray(a)
    if arr.dtype == bool:
        return arr.tolist()
    lst = arr.astype(np.float64).tolist()
    if np.all(np.isfinite(arr)):
        return lst
    return json.loads(json.dumps(lst).replace("NaN", "null").replace("-Infinity", "null").replace("Infinity", "null"))


def _check_shape(name: str, a: Any, shape: tuple[int, ...]) -> np.ndarray:
    """Return ``a`` as an array of ``shape`` or raise naming the field."""
    arr = np.asarray(a)
    if arr.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {arr.shape}")
    return arr


class G1LogWriter:
    """Write one G1 run to an MCAP file.

    Per-joint arrays are given in ``metadata.joint_names`` order (canonical G1 order by default). Times ``t``
    are seconds since ``cfg.start_time_ns``. The file is written to ``<path>.part`` and renamed on
    :meth:`close`, so an interrupted run leaves a readable (truncated) ``.part`` file and never a
    half-written file under the final name.

    Example:
        >>> with G1LogWriter("run.mcap", RunMetadata(controller="policy")) as w:  # doctest: +SKIP
        ...     w.write_lowstate(0.0, q, dq, tau, quat, gyro, acc)
    """

    def __init__(self, path: str | os.PathLike, metadata: RunMetadata, cfg: LogWriterCfg | None = None) -> None:
        """Open the file, write the header, the schemas of ``cfg.topics`` and the run metadata."""
        from mcap.writer import CompressionType, Writer

        self.cfg = cfg or LogWriterCfg()
        self.path = Path(path)
        if self.path.exists() and not self.cfg.overwrite:
            raise FileExistsError(f"{self.path} exists; refusing to overwrite it (set LogWriterCfg.overwrite=True)")
        if len(metadata.joint_names) != G1_NUM_JOINTS:
            raise ValueError(f"metadata.joint_names has {len(metadata.joint_names)} names, the G1 has {G1_NUM_JOINTS}")
        self.metadata = metadata
        self._part = self.path.with_name(self.path.name + ".part")
        self._file = open(self._part, "wb")  # noqa: SIM115 (closed in close())
        compression = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4, "none": CompressionType.NONE}
        self._mcap = Writer(self._file, chunk_size=self.cfg.chunk_size, compression=compression[self.cfg.compression])
        self._mcap.start(profile="", library="gmloco-deploy")
        self._channels: dict[str, int] = {}
        self._counts: dict[str, int] = {}
        for topic in self.cfg.topics:
            self._channel(topic)
        record = metadata.to_record()
        record["channel_map"] = json.dumps(
            {
                str(cid): [topic, TOPICS[topic].encoding, TOPICS[topic].schema_name]
                for topic, cid in self._channels.items()
            }
        )
        self._mcap.add_metadata(METADATA_RUN, record)
        self._closed = False

    # -- channels ---------------------------------------------------------------------------------

    def _channel(self, topic: str, channel_metadata: dict[str, str] | None = None) -> int:
        """Return the channel id of a topic, registering schema and channel on first use."""
        if topic in self._channels:
            return self._channels[topic]
        spec = TOPICS[topic]
        if spec.encoding == "protobuf":
            from mcap_protobuf.schema import register_schema

            schema_id = register_schema(self._mcap, _proto_class(spec.schema_name))
        else:
            schema_id = self._mcap.register_schema(spec.schema_name, "jsonschema", json_schema(spec))
        per_joint = any(JOINT_DIM in f.shape for f in spec.fields)
        meta = {"joint_names": json.dumps(list(self.metadata.joint_names))} if per_joint else {}
        meta.update(channel_metadata or {})
        cid = self._mcap.register_channel(topic, spec.encoding, schema_id, meta)
        self._channels[topic] = cid
        return cid

    def declare(self, topic: str, **channel_metadata: Any) -> None:
        """Declare a topic with channel metadata (e.g. eta ``names``/``units``, observation ``terms``).

        Values that are not strings are stored as JSON. Must be called before the topic's first message.
        """
        if topic in self._channels:
            raise ValueError(f"{topic} is already declared; declare it before its first message")
        meta = {k: v if isinstance(v, str) else json.dumps(v) for k, v in channel_metadata.items()}
        self._channel(topic, meta)

    def _write(self, topic: str, t: float, data: bytes, publish_time: float | None, sequence: int | None) -> None:
        """Add one serialized message."""
        if self._closed:
            raise RuntimeError(f"{self.path} is closed")
        if not math.isfinite(t):
            raise ValueError(f"{topic}: non-finite time {t}")
        n = self._counts.get(topic, 0)
        log_ns = self.cfg.start_time_ns + _ns(t)
        pub_ns = log_ns if publish_time is None else self.cfg.start_time_ns + _ns(publish_time)
        seq = n if sequence is None else int(sequence) & 0xFFFFFFFF
        self._mcap.add_message(self._channel(topic), log_time=log_ns, data=data, publish_time=pub_ns, sequence=seq)
        self._counts[topic] = n + 1

    def _write_json(self, topic: str, t: float, msg: dict, publish_time: float | None, seq: int | None) -> None:
        """Serialize and add a JSON message."""
        self._write(topic, t, json.dumps(msg, separators=(",", ":")).encode(), publish_time, seq)

    # -- topics -------------------------------------------------------------------------------------

    def write_lowstate(
        self,
        t: float,
        q: np.ndarray,
        dq: np.ndarray,
        tau_est: np.ndarray,
        quaternion: np.ndarray,
        gyroscope: np.ndarray,
        accelerometer: np.ndarray,
        *,
        ddq: np.ndarray | None = None,
        rpy: np.ndarray | None = None,
        tick: int | None = None,
        publish_time: float | None = None,
    ) -> None:
        """Write one LowState sample: ``/lowstate/joint_states`` and ``/lowstate/imu``.

        Args:
            t: Log time [s].
            q: Joint positions [rad], shape [29].
            dq: Joint velocities [rad/s], shape [29].
            tau_est: Estimated joint torques [N*m], shape [29].
            quaternion: IMU orientation (w, x, y, z), shape [4].
            gyroscope: IMU angular velocity in the IMU frame [rad/s], shape [3].
            accelerometer: IMU specific force in the IMU frame [m/s^2], shape [3] (+9.81 on z at rest).
            ddq: Joint accelerations [rad/s^2], shape [29], optional.
            rpy: IMU roll, pitch, yaw [rad], shape [3], optional.
            tick: LowState ``tick`` (stored as the MCAP message sequence); a counter when omitted.
            publish_time: Robot-side time [s] when the sample was produced; ``t`` when omitted.
        """
        from foxglove_schemas_protobuf.JointState_pb2 import JointState
        from foxglove_schemas_protobuf.JointStates_pb2 import JointStates

        j = (G1_NUM_JOINTS,)
        q, dq, tau_est = (_check_shape(n, a, j) for n, a in (("q", q), ("dq", dq), ("tau_est", tau_est)))
        acc = _check_shape("ddq", ddq, j) if ddq is not None else None
        msg = JointStates()
        stamp = self.cfg.start_time_ns + _ns(t if publish_time is None else publish_time)
        msg.timestamp.FromNanoseconds(stamp)
        for i, name in enumerate(self.metadata.joint_names):
            js = JointState(name=name, position=float(q[i]), velocity=float(dq[i]), effort=float(tau_est[i]))
            if acc is not None:
                js.acceleration = float(acc[i])
            msg.joints.append(js)
        self._write(TOPIC_JOINT_STATES, t, msg.SerializeToString(), publish_time, tick)
        imu = {
            "quaternion": _jsonable(_check_shape("quaternion", quaternion, (4,))),
            "gyroscope": _jsonable(_check_shape("gyroscope", gyroscope, (3,))),
            "accelerometer": _jsonable(_check_shape("accelerometer", accelerometer, (3,))),
        }
        if rpy is not None:
            imu["rpy"] = _jsonable(_check_shape("rpy", rpy, (3,)))
        self._write_json(TOPIC_IMU, t, imu, publish_time, tick)

    def write_lowcmd(
        self,
        t: float,
        q: np.ndarray,
        dq: np.ndarray,
        kp: np.ndarray,
        kd: np.ndarray,
        tau: np.ndarray,
        *,
        publish_time: float | None = None,
        sequence: int | None = None,
    ) -> None:
        """Write one LowCmd sample (targets [rad], [rad/s], gains [N*m/rad], [N*m*s/rad], feed-forward [N*m]), each [29]."""
        j = (G1_NUM_JOINTS,)
        msg = {
            n: _jsonable(_check_shape(n, a, j)) for n, a in (("q", q), ("dq", dq), ("kp", kp), ("kd", kd), ("tau", tau))
        }
        self._write_json(TOPIC_LOWCMD, t, msg, publish_time, sequence)

    def write_motor_aux(self, t: float, temperature: np.ndarray, vol: np.ndarray) -> None:
        """Write motor temperatures [degC], shape [29, 2], and voltages [V], shape [29]."""
        msg = {
            "temperature": _jsonable(_check_shape("temperature", temperature, (G1_NUM_JOINTS, 2))),
            "vol": _jsonable(_check_shape("vol", vol, (G1_NUM_JOINTS,))),
        }
        self._write_json(TOPIC_MOTOR_AUX, t, msg, None, None)

    def write_odometry(
        self,
        t: float,
        position: np.ndarray,
        orientation: np.ndarray,
        linear_velocity: np.ndarray,
        angular_velocity: np.ndarray,
        *,
        tf: bool = True,
    ) -> None:
        """Write the base state (odometry) and, when ``tf``, the ``odom -> pelvis`` transform.

        Args:
            t: Log time [s].
            position: Pelvis position in ``odom`` [m], shape [3].
            orientation: Pelvis orientation (w, x, y, z), shape [4].
            linear_velocity: Linear velocity in the pelvis frame [m/s], shape [3].
            angular_velocity: Angular velocity in the pelvis frame [rad/s], shape [3].
            tf: Also write ``/tf`` for Foxglove's 3D panel.
        """
        from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
        from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
        from foxglove_schemas_protobuf.Odometry_pb2 import Odometry

        p = _check_shape("position", position, (3,))
        o = _check_shape("orientation", orientation, (4,))
        v = _check_shape("linear_velocity", linear_velocity, (3,))
        w = _check_shape("angular_velocity", angular_velocity, (3,))
        msg = Odometry(frame_id="odom", body_frame_id="pelvis")
        msg.timestamp.FromNanoseconds(self.cfg.start_time_ns + _ns(t))
        _set_pose(msg.pose, p, o)
        msg.linear_velocity.x, msg.linear_velocity.y, msg.linear_velocity.z = (float(x) for x in v)
        msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = (float(x) for x in w)
        self._write(TOPIC_ODOMETRY, t, msg.SerializeToString(), None, None)
        if tf:
            tr = FrameTransform(parent_frame_id="odom", child_frame_id="pelvis")
            tr.timestamp.CopyFrom(msg.timestamp)
            tr.translation.x, tr.translation.y, tr.translation.z = (float(x) for x in p)
            tr.rotation.w, tr.rotation.x, tr.rotation.y, tr.rotation.z = (float(x) for x in o)
            self._write(TOPIC_TF, t, FrameTransforms(transforms=[tr]).SerializeToString(), None, None)

    def write_command(self, t: float, lin_vel_x: float, lin_vel_y: float = 0.0, ang_vel_z: float = 0.0) -> None:
        """Write the velocity command: forward and lateral [m/s] in the heading frame, yaw rate [rad/s]."""
        msg = {"lin_vel_x": float(lin_vel_x), "lin_vel_y": float(lin_vel_y), "ang_vel_z": float(ang_vel_z)}
        self._write_json(TOPIC_COMMAND, t, msg, None, None)

    def write_policy(self, t: float, observation: np.ndarray | None = None, action: np.ndarray | None = None) -> None:
        """Write the policy observation [n_obs] and/or raw action [n_act] of one control step."""
        if observation is not None:
            self._write_json(TOPIC_POLICY_OBS, t, {"observation": _jsonable(np.ravel(observation))}, None, None)
        if action is not None:
            self._write_json(TOPIC_POLICY_ACTION, t, {"action": _jsonable(np.ravel(action))}, None, None)

    def write_eta(self, t: float, eta: np.ndarray) -> None:
        """Write the student's decoded eta [K] (declare ``names``/``units`` first with :meth:`declare`)."""
        self._write_json(TOPIC_ETA, t, {"eta": _jsonable(np.ravel(eta))}, None, None)

    def write_sim_contact(self, t: float, in_contact: np.ndarray, force: np.ndarray, sinkage: np.ndarray) -> None:
        """Write privileged foot contact truth: flags [2], world forces [N] [2, 3], sinkage [m] [2]."""
        nf = len(G1_FEET)
        msg = {
            "in_contact": _jsonable(_check_shape("in_contact", np.asarray(in_contact, bool), (nf,))),
            "force": _jsonable(_check_shape("force", force, (nf, 3))),
            "sinkage": _jsonable(_check_shape("sinkage", sinkage, (nf,))),
        }
        self._write_json(TOPIC_SIM_CONTACT, t, msg, None, None)

    def write_log(self, t: float, message: str, level: Literal["DEBUG", "INFO", "WARNING", "ERROR"] = "INFO") -> None:
        """Write a text event to ``/log`` (Foxglove's Log panel)."""
        from foxglove_schemas_protobuf.Log_pb2 import Log

        msg = Log(message=message, name="gmloco", level=getattr(Log.Level, level))
        msg.timestamp.FromNanoseconds(self.cfg.start_time_ns + _ns(t))
        self._write(TOPIC_LOG, t, msg.SerializeToString(), None, None)

    # -- lifecycle ----------------------------------------------------------------------------------

    def close(self, end_reason: str = "completed", **extra: str) -> Path:
        """Write the end record and the summary, and move ``<path>.part`` to ``path``."""
        if self._closed:
            return self.path
        end = {"end_reason": end_reason, **{k: str(v) for k, v in extra.items()}}
        end.update({f"count:{topic}": str(n) for topic, n in self._counts.items()})
        self._mcap.add_metadata(METADATA_RUN_END, end)
        self._mcap.finish()
        self._file.close()
        os.replace(self._part, self.path)
        self._closed = True
        return self.path

    def __enter__(self) -> G1LogWriter:
        """Return self."""
        return self

    def __exit__(self, exc_type: object, exc: object, tb: object) -> None:
        """Close the file; an exception is recorded as the end reason."""
        self.close("completed" if exc_type is None else f"exception: {exc!r}")


def _set_pose(pose: Any, p: np.ndarray, o: np.ndarray) -> None:
    """Fill a ``foxglove.Pose`` from a position and a (w, x, y, z) quaternion."""
    pose.position.x, pose.position.y, pose.position.z = (float(x) for x in p)
    pose.orientation.w, pose.orientation.x, pose.orientation.y, pose.orientation.z = (float(x) for x in o)


def _proto_class(full_name: str) -> Any:
    """Return the generated Foxglove protobuf class for ``foxglove.<Name>``."""
    import importlib

    name = full_name.split(".")[-1]
    return getattr(importlib.import_module(f"foxglove_schemas_protobuf.{name}_pb2"), name)
