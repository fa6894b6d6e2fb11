# SPDX-License-Identifier: Apache-2.0
"""Decode the messages of one topic into per-field numpy arrays in canonical G1 joint order."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

import numpy as np

from gmloco.deploy.g1 import G1_JOINT_NAMES, G1_NUM_JOINTS
from gmloco.deploy.logs.errors import JointOrderError, LogFormatError
from gmloco.deploy.logs.schema import JOINT_DIM, TopicSpec

__all__ = ["decode_topic", "joint_permutation", "protobuf_decoder"]


def joint_permutation(names: list[str] | tuple[str, ...], where: str) -> np.ndarray:
    """Return ``perm`` with ``canonical[perm[i]] == names[i]``, or raise naming unknown / missing joints.

    Args:
        names: Joint names in file order.
        where: Where the names come from (for the error message).

    Raises:
        JointOrderError: On a wrong count, unknown, missing or duplicated names.
    """
    names = list(names)
    unknown = [n for n in names if n not in G1_JOINT_NAMES]
    missing = [n for n in G1_JOINT_NAMES if n not in names]
    dup = sorted({n for n in names if names.count(n) > 1})
    if len(names) != G1_NUM_JOINTS or unknown or missing or dup:
        raise JointOrderError(
            f"{where}: {len(names)} joints, expected the {G1_NUM_JOINTS} joints of the 29-DoF G1"
            + (f"; unknown names {unknown}" if unknown else "")
            + (f"; missing {missing}" if missing else "")
            + (f"; duplicated {dup}" if dup else "")
            + ". Map the robot's motor indices to gmloco.deploy.logs.G1_JOINT_NAMES (see SCHEMA.md, joint table) "
            "before logging; a 23-DoF G1 is not supported."
        )
    return np.array([G1_JOINT_NAMES.index(n) for n in names])


def protobuf_decoder(channel: Any, schema: Any | None, spec: TopicSpec) -> Callable[[bytes], Any]:
    """Return a bytes -> message decoder from the file's schema, else from the installed Foxglove classes."""
    if schema is not None and schema.data:
        from mcap_protobuf.decoder import DecoderFactory

        dec = DecoderFactory().decoder_for(channel.message_encoding, schema)
        if dec is not None:
            return dec
    import importlib

    name = spec.schema_name.split(".")[-1]
    cls = getattr(importlib.import_module(f"foxglove_schemas_protobuf.{name}_pb2"), name)
    return cls.FromString


def _nan_array(value: Any) -> np.ndarray:
    """Convert nested JSON lists to float64, ``null`` to NaN."""
    if isinstance(value, list):
        return np.array([_nan_array(v) for v in value], dtype=np.float64) if value else np.zeros(0)
    return np.array(np.nan if value is None else value, dtype=np.float64)


def _fixed_shape(shape: tuple[int | str, ...], k: int | None) -> tuple[int, ...] | None:
    """Resolve ``J``/``K`` in a field shape; ``None`` when ``K`` is free."""
    out = []
    for d in shape:
        if d == JOINT_DIM:
            out.append(G1_NUM_JOINTS)
        elif d == "K":
            if k is None:
                return None
            out.append(k)
        else:
            out.append(int(d))
    return tuple(out)


def _decode_json(spec: TopicSpec, payloads: list[bytes], perm: np.ndarray | None) -> tuple[dict, list[int]]:
    """Decode JSON messages; return field arrays and the indices of messages that failed to decode."""
    cols: dict[str, list] = {f.name: [] for f in spec.fields}
    bad: list[int] = []
    shapes: dict[str, tuple[int, ...] | None] = {f.name: _fixed_shape(f.shape, None) for f in spec.fields}
    for i, raw in enumerate(payloads):
        try:
            msg = json.loads(raw)
            row = {}
            for f in spec.fields:
                if f.name not in msg:
                    row[f.name] = None
                    continue
                a = _nan_array(msg[f.name])
                if shapes[f.name] is None:  # first message fixes K
                    shapes[f.name] = a.shape
                if a.shape != shapes[f.name]:
                    if JOINT_DIM in f.shape and a.ndim >= 1 and a.shape[0] != G1_NUM_JOINTS:
                        raise JointOrderError(
                            f"{spec.topic}: field {f.name!r} of message {i} has {a.shape[0]} joints, expected "
                            f"{G1_NUM_JOINTS} (G1 29-DoF). Log all 29 joints in G1_JOINT_NAMES order."
                        )
                    raise LogFormatError(f"{spec.topic}: field {f.name!r} shape {a.shape} != {shapes[f.name]}")
                row[f.name] = a
        except JointOrderError:
            raise
        except (ValueError, TypeError, LogFormatError):
            bad.append(i)
            continue
        for k, v in row.items():
            cols[k].append(v)
    out = {}
    for f in spec.fields:
        vals = cols[f.name]
        if all(v is None for v in vals):
            continue  # optional field absent
        shape = shapes[f.name] or ()
        arr = np.stack([np.full(shape, np.nan) if v is None else v for v in vals]) if vals else np.zeros((0, *shape))
        if perm is not None and JOINT_DIM in f.shape and arr.size:
            arr = _to_canonical(arr, perm)
        out[f.name] = arr.astype(bool) if f.unit == "bool" else arr
    return out, bad


def _to_canonical(arr: np.ndarray, perm: np.ndarray) -> np.ndarray:
    """Reorder axis 1 (joints) of ``arr`` from file order to canonical order."""
    out = np.empty_like(arr)
    out[:, perm] = arr
    return out


def _decode_joint_states(decode: Callable[[bytes], Any], payloads: list[bytes], topic: str) -> tuple[dict, list[int]]:
    """Decode ``foxglove.JointStates`` messages, mapping joint names to canonical order."""
    n = len(payloads)
    out = {k: np.full((n, G1_NUM_JOINTS), np.nan) for k in ("q", "dq", "ddq", "tau_est")}
    keep = np.ones(n, bool)
    bad: list[int] = []
    cache: dict[tuple[str, ...], np.ndarray] = {}
    for i, raw in enumerate(payloads):
        try:
            msg = decode(raw)
        except Exception:
            bad.append(i)
            keep[i] = False
            continue
        names = tuple(j.name for j in msg.joints)
        if names not in cache:
            cache[names] = joint_permutation(names, f"{topic} message {i}")
        perm = cache[names]
        for k, j in enumerate(msg.joints):
            c = perm[k]
            out["q"][i, c], out["dq"][i, c], out["tau_est"][i, c] = j.position, j.velocity, j.effort
            if j.HasField("acceleration"):
                out["ddq"][i, c] = j.acceleration
    out = {k: v[keep] for k, v in out.items()}
    if np.isnan(out["ddq"]).all():
        del out["ddq"]
    return out, bad


def _decode_odometry(decode: Callable[[bytes], Any], payloads: list[bytes]) -> tuple[dict, list[int]]:
    """Decode ``foxglove.Odometry`` into position, orientation (w, x, y, z) and body-frame velocities."""
    rows, bad = [], []
    for i, raw in enumerate(payloads):
        try:
            m = decode(raw)
        except Exception:
            bad.append(i)
            continue
        p, o, v, w = m.pose.position, m.pose.orientation, m.linear_velocity, m.angular_velocity
        rows.append([p.x, p.y, p.z, o.w, o.x, o.y, o.z, v.x, v.y, v.z, w.x, w.y, w.z])
    a = np.array(rows, dtype=np.float64).reshape(-1, 13)
    return {
        "position": a[:, 0:3],
        "orientation": a[:, 3:7],
        "linear_velocity": a[:, 7:10],
        "angular_velocity": a[:, 10:13],
    }, bad


def decode_topic(
    spec: TopicSpec,
    channel: Any,
    schema: Any | None,
    payloads: list[bytes],
    file_joint_names: tuple[str, ...],
) -> tuple[dict[str, Any], list[int]]:
    """Decode all messages of one topic.

    Args:
        spec: Schema of the topic.
        channel: ``mcap.records.Channel`` (its metadata may carry ``joint_names``).
        schema: ``mcap.records.Schema`` or ``None`` when lost.
        payloads: Message bytes, in time order.
        file_joint_names: Joint order from the run metadata, used when the channel does not say.

    Returns:
        Field arrays (first axis = message) and the indices of undecodable messages (dropped from the arrays).
    """
    if spec.encoding == "json":
        names = file_joint_names
        if channel is not None and "joint_names" in channel.metadata:
            names = tuple(json.loads(channel.metadata["joint_names"]))
        needs_perm = any(JOINT_DIM in f.shape for f in spec.fields)
        perm = joint_permutation(names, f"{spec.topic} joint_names") if needs_perm else None
        return _decode_json(spec, payloads, perm)
    decode = protobuf_decoder(channel, schema, spec)
    if spec.schema_name == "foxglove.JointStates":
        return _decode_joint_states(decode, payloads, spec.topic)
    if spec.schema_name == "foxglove.Odometry":
        return _decode_odometry(decode, payloads)
    if spec.schema_name == "foxglove.Log":
        msgs, bad = [], []
        for i, raw in enumerate(payloads):
            try:
                m = decode(raw)
                msgs.append((int(m.level), m.message))
            except Exception:
                bad.append(i)
        return {"level": np.array([m[0] for m in msgs], int), "message": [m[1] for m in msgs]}, bad
    return {}, []
