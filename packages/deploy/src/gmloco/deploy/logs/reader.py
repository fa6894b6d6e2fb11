# SPDX-License-Identifier: Apache-2.0
"""Read a G1 MCAP log into numpy arrays by signal, joint and time, surviving damaged files."""

from __future__ import annotations

import json
import warnings
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from gmloco.deploy.g1 import G1_JOINT_NAMES, joint_index
from gmloco.deploy.logs.checks import check_contracts
from gmloco.deploy.logs.decode import decode_topic, joint_permutation
from gmloco.deploy.logs.errors import (
    LogContractWarning,
    LogDamageWarning,
    LogFormatError,
    MissingTopicError,
    UnitsError,
)
from gmloco.deploy.logs.mcap_scan import DamageReport, scan_mcap
from gmloco.deploy.logs.metadata import RunMetadata
from gmloco.deploy.logs.schema import (
    METADATA_RUN,
    METADATA_RUN_END,
    SCHEMA_VERSION,
    TOPIC_JOINT_STATES,
    TOPIC_LOG,
    TOPICS,
    UNITS,
    signal_spec,
)

__all__ = ["ChannelData", "G1Log", "ReadCfg", "read_log"]


@dataclass
class ReadCfg:
    """Settings of :func:`read_log`."""

    time_source: Literal["log_time", "publish_time"] = "log_time"
    """Which MCAP timestamp defines a sample's time (both are kept in :class:`ChannelData`)."""
    check_units: bool = True
    """Refuse files whose declared units differ from the schema (:class:`UnitsError`)."""
    check_contracts: bool = True
    """Warn on implausible magnitudes (degrees for radians, accelerometer in g, quaternion order)."""


@dataclass
class ChannelData:
    """All decoded messages of one topic, in time order."""

    topic: str
    """MCAP topic."""
    time_ns: np.ndarray
    """Sample times per :attr:`ReadCfg.time_source` [ns], shape [N], int64."""
    log_time_ns: np.ndarray
    """MCAP log_time [ns], shape [N]."""
    publish_time_ns: np.ndarray
    """MCAP publish_time [ns], shape [N]."""
    sequence: np.ndarray
    """MCAP sequence (LowState ``tick`` on lowstate topics), shape [N]."""
    fields: dict[str, Any]
    """Field arrays, first axis N, per-joint axes in canonical G1 order."""
    metadata: dict[str, str] = field(default_factory=dict)
    """Channel metadata (eta names/units, observation terms, ...)."""


@dataclass
class G1Log:
    """A decoded G1 run. Times returned by :meth:`signal` are seconds since :attr:`t0_ns`."""

    path: Path
    """File it was read from."""
    metadata: RunMetadata
    """Run metadata (``gmloco.run`` record)."""
    channels: dict[str, ChannelData]
    """Decoded topics with at least one message."""
    t0_ns: int
    """Time of the first joint-state sample [ns]; origin of all relative times."""
    damage: list[DamageReport] = field(default_factory=list)
    """Where the file was damaged (empty when intact)."""
    run_end: dict[str, str] | None = None
    """``gmloco.run_end`` record, ``None`` when the run was cut before it was written."""
    unknown_topics: tuple[str, ...] = ()
    """Topics in the file that the schema does not define (ignored)."""
    joint_names: tuple[str, ...] = G1_JOINT_NAMES
    """Joint order of every per-joint array returned (canonical G1 order)."""

    def has(self, signal: str) -> bool:
        """Whether the log holds a signal (e.g. ``"odom.linear_velocity"``, ``"student.eta"``)."""
        spec, f = signal_spec(signal)
        ch = self.channels.get(spec.topic)
        return ch is not None and f.name in ch.fields and len(ch.time_ns) > 0

    def signal(self, signal: str, joint: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Return ``(t, values)`` of one signal at its own sample times.

        Args:
            signal: ``<prefix>.<field>``, e.g. ``"lowstate.tau_est"`` (see :data:`~gmloco.deploy.logs.schema.UNITS`).
            joint: Select one joint by name (per-joint signals only).

        Returns:
            ``t`` [s] since :attr:`t0_ns`, shape [N], and values, shape [N, ...].

        Raises:
            KeyError: If the log does not hold the signal; the message lists what it holds.
        """
        spec, f = signal_spec(signal)
        if not self.has(signal):
            raise KeyError(f"{self.path.name} has no {signal!r} (topic {spec.topic}); it holds {self.signals()}")
        ch = self.channels[spec.topic]
        values = ch.fields[f.name]
        if joint is not None:
            values = values[:, joint_index(joint)]
        return (ch.time_ns - self.t0_ns) * 1e-9, values

    def signals(self) -> list[str]:
        """Names of the signals present."""
        return [s for s in UNITS if self.has(s)]

    def events(self) -> list[tuple[float, int, str]]:
        """Return ``/log`` events as ``(t [s], level, message)``."""
        ch = self.channels.get(TOPIC_LOG)
        if ch is None:
            return []
        t = (ch.time_ns - self.t0_ns) * 1e-9
        return [(float(t[i]), int(ch.fields["level"][i]), ch.fields["message"][i]) for i in range(len(t))]

    def aligned(self, cfg: Any = None) -> Any:
        """Resample onto a common time base; see :func:`gmloco.deploy.logs.align.align`."""
        from gmloco.deploy.logs.align import align

        return align(self, cfg)


def _warn_damage(path: Path, damage: list[DamageReport], t_last_ns: int | None, t0: int | None) -> None:
    """Emit one :class:`LogDamageWarning` per damaged place."""
    for d in damage:
        until = ""
        if t_last_ns is not None and t0 is not None:
            until = f"; data read up to t = {(t_last_ns - t0) * 1e-9:.3f} s"
        lost = ""
        if d.log_time_ns is not None and t0 is not None:
            lost = f"; lost log_time {(d.log_time_ns[0] - t0) * 1e-9:.3f}..{(d.log_time_ns[1] - t0) * 1e-9:.3f} s"
        warnings.warn(
            f"{path}: damaged at byte {d.byte_offset} of {path.stat().st_size} ({d.kind}): {d.detail}{lost}{until}",
            LogDamageWarning,
            stacklevel=3,
        )


def _metadata(path: Path, records: dict[str, dict[str, str]], damage: list[DamageReport]) -> RunMetadata:
    """Parse the run metadata or explain why it is missing."""
    if METADATA_RUN not in records:
        hint = (
            f" The file is damaged at byte {damage[0].byte_offset} ({damage[0].kind}), before the metadata record."
            if damage
            else " Write files with gmloco.deploy.logs.G1LogWriter, or add the record as SCHEMA.md describes."
        )
        raise LogFormatError(f"{path}: no {METADATA_RUN!r} metadata record.{hint}")
    meta = RunMetadata.from_record(records[METADATA_RUN])
    if meta.schema_version.split("/")[0] != SCHEMA_VERSION.split("/")[0]:
        raise LogFormatError(f"{path}: schema {meta.schema_version!r} is not a {SCHEMA_VERSION!r} log")
    return meta


def _check_units(path: Path, meta: RunMetadata) -> None:
    """Refuse declared units that differ from the schema."""
    bad = {s: (u, UNITS[s]) for s, u in meta.units.items() if s in UNITS and u != UNITS[s]}
    if bad:
        lines = ", ".join(f"{s}: file says {u!r}, schema says {e!r}" for s, (u, e) in sorted(bad.items()))
        raise UnitsError(f"{path}: units differ from the schema ({lines}). Convert to SI units before logging.")


def _group(scan: Any, meta_record: dict[str, str]) -> tuple[dict[str, list], dict[str, Any]]:
    """Group messages by topic, recovering lost channel records from the metadata channel map."""
    channels = dict(scan.channels)
    cmap = json.loads(meta_record.get("channel_map", "{}"))
    by_topic: dict[str, list] = defaultdict(list)
    for m in scan.messages:
        ch = channels.get(m.channel_id)
        if ch is None and str(m.channel_id) in cmap:
            by_topic[cmap[str(m.channel_id)][0]].append(m)
        elif ch is not None:
            by_topic[ch.topic].append(m)
    return by_topic, {ch.topic: ch for ch in channels.values()}


def _time_order(path: Path, topic: str, t: np.ndarray) -> np.ndarray:
    """Return a stable sort order of ``t``, warning on backward steps and duplicates."""
    d = np.diff(t)
    back = np.flatnonzero(d < 0)
    if back.size:
        warnings.warn(
            f"{path}: {topic}: {back.size} timestamps go backwards (first after message {back[0]}, "
            f"t = {t[back[0]] * 1e-9:.6f} s -> {t[back[0] + 1] * 1e-9:.6f} s); messages sorted by time. "
            "Check the logger's clock source (use one monotonic clock for all topics).",
            LogContractWarning,
            stacklevel=4,
        )
    dup = int(np.sum(d == 0))
    if dup and topic != TOPIC_LOG:
        warnings.warn(
            f"{path}: {topic}: {dup} duplicated timestamps (repeated samples?); the last of each is used when resampling.",
            LogContractWarning,
            stacklevel=4,
        )
    return np.argsort(t, kind="stable")


def _decode_channel(
    path: Path, topic: str, msgs: list, ch: Any, schemas: dict, meta: RunMetadata, cfg: ReadCfg
) -> ChannelData:
    """Decode one topic's messages into a :class:`ChannelData`."""
    spec = TOPICS[topic]
    t_log = np.array([m.log_time for m in msgs], dtype=np.int64)
    t_pub = np.array([m.publish_time for m in msgs], dtype=np.int64)
    seq = np.array([m.sequence for m in msgs], dtype=np.int64)
    t = t_log if cfg.time_source == "log_time" else t_pub
    order = _time_order(path, topic, t)
    payloads = [msgs[i].data for i in order]
    schema = schemas.get(ch.schema_id) if ch is not None else None
    fields_, bad = decode_topic(spec, ch, schema, payloads, meta.joint_names)
    keep = np.setdiff1d(np.arange(len(order)), bad)
    if bad:
        warnings.warn(
            f"{path}: {topic}: {len(bad)} of {len(order)} messages could not be decoded (first at "
            f"t = {t[order[bad[0]]] * 1e-9:.6f} s); they are skipped.",
            LogDamageWarning,
            stacklevel=3,
        )
    idx = order[keep]
    return ChannelData(topic, t[idx], t_log[idx], t_pub[idx], seq[idx], fields_, dict(ch.metadata) if ch else {})


def read_log(path: str | Path, cfg: ReadCfg | None = None) -> G1Log:
    """Read a G1 MCAP log.

    Damaged files are read up to (or around) the damage, with a :class:`LogDamageWarning` naming the byte
    offset and the time reached. Joint arrays are returned in canonical G1 order whatever the file's order.

    Args:
        path: MCAP file written per SCHEMA.md.
        cfg: Reader settings.

    Returns:
        The decoded log.

    Raises:
        LogFormatError: Not an MCAP file, no run metadata, or malformed fields.
        MissingTopicError: A required topic (joint states, IMU, lowcmd) has no messages.
        JointOrderError: Wrong joint count, unknown or missing joint names.
        UnitsError: Declared units differ from the schema.
    """
    cfg = cfg or ReadCfg()
    path = Path(path)
    scan = scan_mcap(path)
    meta = _metadata(path, scan.metadata, scan.damage)
    joint_permutation(meta.joint_names, f"{path}: run metadata joint_names")
    if cfg.check_units:
        _check_units(path, meta)
    by_topic, channel_by_topic = _group(scan, scan.metadata[METADATA_RUN])
    channels: dict[str, ChannelData] = {}
    for topic, msgs in by_topic.items():
        if topic in TOPICS and msgs:
            channels[topic] = _decode_channel(path, topic, msgs, channel_by_topic.get(topic), scan.schemas, meta, cfg)
    t0 = int(channels[TOPIC_JOINT_STATES].time_ns[0]) if TOPIC_JOINT_STATES in channels else None
    t_last = max((int(c.time_ns[-1]) for c in channels.values() if len(c.time_ns)), default=None)
    _warn_damage(path, scan.damage, t_last, t0)
    missing = [t for t, s in TOPICS.items() if s.required and (t not in channels or len(channels[t].time_ns) == 0)]
    if missing:
        present = sorted(by_topic)
        dmg = f" The file is damaged ({scan.damage[0].detail})." if scan.damage else ""
        raise MissingTopicError(
            f"{path}: required topic(s) {missing} have no messages (topics present: {present}).{dmg} "
            "A G1 log needs /lowstate/joint_states, /lowstate/imu and /lowcmd (see SCHEMA.md); "
            "record LowState and LowCmd, or convert the hardware log with G1LogWriter."
        )
    log = G1Log(
        path=path,
        metadata=meta,
        channels=channels,
        t0_ns=t0 or 0,
        damage=scan.damage,
        run_end=scan.metadata.get(METADATA_RUN_END),
        unknown_topics=tuple(sorted(t for t in by_topic if t not in TOPICS)),
    )
    if cfg.check_contracts:
        check_contracts(log)
    return log
