# SPDX-License-Identifier: Apache-2.0
"""The MCAP schema of a G1 run: topics, fields, units and the run metadata record.

One schema serves the simulator and the real robot. Field names and units follow the Unitree
``unitree_hg`` low-level messages (``LowState_.motor_state[i].{q,dq,ddq,tau_est}``,
``LowState_.imu_state.{quaternion,gyroscope,accelerometer,rpy}``, ``LowCmd_.motor_cmd[i].{q,dq,kp,kd,tau}``)
so that a hardware logger maps onto it field by field. ``packages/deploy/SCHEMA.md`` is the prose version
of this module; a test checks that the two agree on topic names.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Literal

from gmloco.deploy.g1 import G1_NUM_JOINTS

__all__ = [
    "JOINT_DIM",
    "METADATA_RUN",
    "METADATA_RUN_END",
    "SCHEMA_VERSION",
    "TOPICS",
    "TOPIC_COMMAND",
    "TOPIC_ETA",
    "TOPIC_IMU",
    "TOPIC_JOINT_STATES",
    "TOPIC_LOG",
    "TOPIC_LOWCMD",
    "TOPIC_MOTOR_AUX",
    "TOPIC_ODOMETRY",
    "TOPIC_POLICY_ACTION",
    "TOPIC_POLICY_OBS",
    "TOPIC_SIM_CONTACT",
    "TOPIC_TF",
    "UNITS",
    "FieldSpec",
    "TopicSpec",
    "json_schema",
    "signal_spec",
]

SCHEMA_VERSION: str = "gmloco.g1_log/1"
"""Written to the run metadata; bumped on any incompatible change of topics, fields or units."""

METADATA_RUN: str = "gmloco.run"
"""Name of the MCAP metadata record written before the first message (see :class:`RunMetadata`)."""

METADATA_RUN_END: str = "gmloco.run_end"
"""Name of the optional metadata record written on close (end reason, message counts)."""

JOINT_DIM: str = "J"
"""Placeholder in :attr:`FieldSpec.shape` for the joint axis (29 on the G1)."""

TOPIC_JOINT_STATES = "/lowstate/joint_states"
TOPIC_IMU = "/lowstate/imu"
TOPIC_MOTOR_AUX = "/lowstate/motor_aux"
TOPIC_LOWCMD = "/lowcmd"
TOPIC_ODOMETRY = "/odometry"
TOPIC_TF = "/tf"
TOPIC_COMMAND = "/command/velocity"
TOPIC_POLICY_OBS = "/policy/observation"
TOPIC_POLICY_ACTION = "/policy/action"
TOPIC_ETA = "/student/eta"
TOPIC_SIM_CONTACT = "/sim/foot_contact"
TOPIC_LOG = "/log"


@dataclass(frozen=True)
class FieldSpec:
    """One field of a topic, exposed by the reader as the signal ``<prefix>.<name>``."""

    name: str
    """Field name: the JSON key, or the logical name of a protobuf field (mapping in SCHEMA.md)."""
    unit: str
    """SI unit ("rad", "rad/s", "N*m", ...), "1" for dimensionless, "bool" for flags."""
    shape: tuple[int | str, ...]
    """Per-sample shape; ``"J"`` is the joint axis, ``"K"`` a length fixed per channel (e.g. eta)."""
    doc: str
    """One-line description, with the Unitree field it mirrors."""


@dataclass(frozen=True)
class TopicSpec:
    """One topic of the schema."""

    topic: str
    """MCAP channel topic."""
    prefix: str
    """Signal-name prefix used by the reader (``lowstate``, ``imu``, ``lowcmd``, ...)."""
    encoding: Literal["protobuf", "json"]
    """MCAP message encoding."""
    schema_name: str
    """Protobuf full name (``foxglove.JointStates``) or JSON-schema title (``gmloco.LowCmd``)."""
    required: bool
    """A file without messages on a required topic is refused by the reader."""
    interpolation: Literal["linear", "hold", "quat", "none"]
    """How the reader resamples it: linear for sampled states, hold for piecewise-constant commands,
    normalized lerp for quaternions, none for event streams."""
    fields: tuple[FieldSpec, ...]
    """Fields of one message."""
    doc: str
    """What the topic carries and at what rate."""


_J = (JOINT_DIM,)
TOPICS: dict[str, TopicSpec] = {
    t.topic: t
    for t in (
        TopicSpec(
            TOPIC_JOINT_STATES,
            "lowstate",
            "protobuf",
            "foxglove.JointStates",
            True,
            "linear",
            (
                FieldSpec("q", "rad", _J, "motor_state.q -> JointState.position"),
                FieldSpec("dq", "rad/s", _J, "motor_state.dq -> JointState.velocity"),
                FieldSpec("ddq", "rad/s^2", _J, "motor_state.ddq -> JointState.acceleration (optional)"),
                FieldSpec("tau_est", "N*m", _J, "motor_state.tau_est -> JointState.effort"),
            ),
            "Joint states at the LowState rate (500 Hz on the robot); joint names in every message.",
        ),
        TopicSpec(
            TOPIC_IMU,
            "imu",
            "json",
            "gmloco.LowStateImu",
            True,
            "linear",
            (
                FieldSpec("quaternion", "1", (4,), "imu_state.quaternion, (w, x, y, z), IMU frame in world"),
                FieldSpec("gyroscope", "rad/s", (3,), "imu_state.gyroscope, angular velocity in IMU frame"),
                FieldSpec("accelerometer", "m/s^2", (3,), "imu_state.accelerometer, specific force (+g up at rest)"),
                FieldSpec("rpy", "rad", (3,), "imu_state.rpy, roll/pitch/yaw (optional)"),
            ),
            "Pelvis IMU (LowState imu_state) at the LowState rate; quaternion interpolated by normalized lerp.",
        ),
        TopicSpec(
            TOPIC_MOTOR_AUX,
            "motor",
            "json",
            "gmloco.MotorAux",
            False,
            "linear",
            (
                FieldSpec("temperature", "degC", (JOINT_DIM, 2), "motor_state.temperature[2] (winding, casing)"),
                FieldSpec("vol", "V", _J, "motor_state.vol"),
            ),
            "Slow motor diagnostics (thermal derating, battery sag); a few Hz is enough.",
        ),
        TopicSpec(
            TOPIC_LOWCMD,
            "lowcmd",
            "json",
            "gmloco.LowCmd",
            True,
            "hold",
            (
                FieldSpec("q", "rad", _J, "motor_cmd.q, position target"),
                FieldSpec("dq", "rad/s", _J, "motor_cmd.dq, velocity target"),
                FieldSpec("kp", "N*m/rad", _J, "motor_cmd.kp"),
                FieldSpec("kd", "N*m*s/rad", _J, "motor_cmd.kd"),
                FieldSpec("tau", "N*m", _J, "motor_cmd.tau, feed-forward torque"),
            ),
            "Commands as sent to the motors; tau_motor = kp (q - q_m) + kd (dq - dq_m) + tau.",
        ),
        TopicSpec(
            TOPIC_ODOMETRY,
            "odom",
            "protobuf",
            "foxglove.Odometry",
            False,
            "linear",
            (
                FieldSpec("position", "m", (3,), "pose.position of body_frame_id (pelvis) in frame_id (odom)"),
                FieldSpec("orientation", "1", (4,), "pose.orientation (w, x, y, z)"),
                FieldSpec("linear_velocity", "m/s", (3,), "linear velocity in the body frame"),
                FieldSpec("angular_velocity", "rad/s", (3,), "angular velocity in the body frame"),
            ),
            "Base state from an estimator, mocap or the simulator (ground truth); optional.",
        ),
        TopicSpec(
            TOPIC_TF,
            "tf",
            "protobuf",
            "foxglove.FrameTransforms",
            False,
            "none",
            (),
            "odom -> pelvis transform for Foxglove's 3D panel; duplicates /odometry, ignored by the reader.",
        ),
        TopicSpec(
            TOPIC_COMMAND,
            "command",
            "json",
            "gmloco.VelocityCommand",
            False,
            "hold",
            (
                FieldSpec("lin_vel_x", "m/s", (), "forward velocity command, heading (yaw) frame"),
                FieldSpec("lin_vel_y", "m/s", (), "lateral velocity command, heading frame"),
                FieldSpec("ang_vel_z", "rad/s", (), "yaw-rate command"),
            ),
            "Velocity command given to the controller (joystick or script) at the control rate.",
        ),
        TopicSpec(
            TOPIC_POLICY_OBS,
            "policy",
            "json",
            "gmloco.PolicyObservation",
            False,
            "hold",
            (FieldSpec("observation", "1", ("K",), "policy input vector; term layout in channel metadata"),),
            "Policy observation at the control rate; channel metadata 'terms' = JSON [[name, size], ...].",
        ),
        TopicSpec(
            TOPIC_POLICY_ACTION,
            "policy",
            "json",
            "gmloco.PolicyAction",
            False,
            "hold",
            (FieldSpec("action", "1", ("K",), "raw policy output (before action scale and default pose)"),),
            "Policy action at the control rate; channel metadata 'action_scale' and 'joint_names'.",
        ),
        TopicSpec(
            TOPIC_ETA,
            "student",
            "json",
            "gmloco.DecodedEta",
            False,
            "hold",
            (FieldSpec("eta", "1", ("K",), "student's decoded terrain parameters"),),
            "Decoded eta at the control rate; channel metadata 'names' and 'units' (JSON lists).",
        ),
        TopicSpec(
            TOPIC_SIM_CONTACT,
            "sim",
            "json",
            "gmloco.SimFootContact",
            False,
            "hold",
            (
                FieldSpec("in_contact", "bool", (2,), "foot in contact (left, right), privileged"),
                FieldSpec("force", "N", (2, 3), "ground reaction force on each foot, world frame"),
                FieldSpec("sinkage", "m", (2,), "intrusion depth below the free surface (0 on rigid ground)"),
            ),
            "Privileged simulator truth for segmentation checks and mismatch discovery; never on hardware.",
        ),
        TopicSpec(
            TOPIC_LOG,
            "log",
            "protobuf",
            "foxglove.Log",
            False,
            "none",
            (),
            "Text events (stage changes, falls, operator notes); returned as (time, level, message).",
        ),
    )
}
"""Every topic of the schema, by topic name."""

UNITS: dict[str, str] = {f"{t.prefix}.{f.name}": f.unit for t in TOPICS.values() for f in t.fields}
"""Unit of every signal, ``{"lowstate.q": "rad", ...}``; also written into the run metadata."""


def signal_spec(signal: str) -> tuple[TopicSpec, FieldSpec]:
    """Return the topic and field of a signal name such as ``"lowstate.tau_est"``.

    Raises:
        KeyError: If no topic defines the signal.
    """
    for spec in TOPICS.values():
        for field in spec.fields:
            if f"{spec.prefix}.{field.name}" == signal:
                return spec, field
    raise KeyError(f"unknown signal {signal!r}; known signals: {sorted(UNITS)}")


def _json_field_schema(field: FieldSpec) -> dict:
    """Return the JSON schema of one field (nested arrays of numbers)."""
    if field.unit == "bool":
        leaf: dict = {"type": "boolean"}
    else:
        leaf = {"type": "number"}
    schema = leaf
    for dim in reversed(field.shape):
        schema = {"type": "array", "items": schema}
        size = G1_NUM_JOINTS if dim == JOINT_DIM else dim
        if isinstance(size, int):
            schema["minItems"] = schema["maxItems"] = size
    schema["description"] = f"{field.doc} [{field.unit}]"
    return schema


def json_schema(spec: TopicSpec) -> bytes:
    """Return the JSON schema (draft 2020-12) of a JSON topic, as written into the MCAP file."""
    if spec.encoding != "json":
        raise ValueError(f"{spec.topic} is a {spec.encoding} topic")
    schema = {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": spec.schema_name,
        "description": spec.doc,
        "type": "object",
        "properties": {f.name: _json_field_schema(f) for f in spec.fields},
    }
    return json.dumps(schema, separators=(",", ":")).encode()
