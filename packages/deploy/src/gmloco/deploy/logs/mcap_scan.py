# SPDX-License-Identifier: Apache-2.0
"""Damage-tolerant MCAP scan: every readable record of a file, and where and how the rest was lost.

The stock ``mcap`` readers either trust the summary at the end of the file (absent when a recording was cut)
or stop at the first bad byte. Robot logs are often cut (power loss, full disk) or damaged, so this module
walks the data section record by record itself and parses each record with ``mcap``'s own record classes:

* a file that ends inside a record is read up to that record; when the cut falls inside a compressed chunk,
  the readable prefix of that chunk is salvaged message by message (zstd streams decode incrementally);
* a chunk whose CRC or decompression fails is skipped and reported with the log-time range it covered;
* a record with an impossible opcode or length (corrupted framing) triggers a resync: the scan searches
  forward for the next chunk that decompresses with a valid CRC and continues from there.

Schemas and channels are collected from everywhere they appear (chunks and summary), so messages stay
decodable when the chunk that first declared their channel is lost but the summary survived.
"""

from __future__ import annotations

import io
import struct
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

__all__ = ["DamageReport", "ScanResult", "scan_mcap"]

_MAGIC = b"\x89MCAP0\r\n"
_OP_NAMES = {
    0x01: "Header",
    0x02: "Footer",
    0x03: "Schema",
    0x04: "Channel",
    0x05: "Message",
    0x06: "Chunk",
    0x07: "MessageIndex",
    0x08: "ChunkIndex",
    0x09: "Attachment",
    0x0A: "AttachmentIndex",
    0x0B: "Statistics",
    0x0C: "Metadata",
    0x0D: "MetadataIndex",
    0x0E: "SummaryOffset",
    0x0F: "DataEnd",
}
_MAX_RESYNC_CANDIDATES = 200_000


@dataclass
class DamageReport:
    """One place where a file could not be read."""

    kind: Literal["truncated", "corrupted_chunk", "corrupted_record", "no_footer"]
    """What went wrong."""
    byte_offset: int
    """Offset of the damaged record (or of the end of the file) [bytes]."""
    detail: str
    """Human-readable explanation, naming what was lost and what was salvaged."""
    log_time_ns: tuple[int, int] | None = None
    """Log-time range of the lost messages [ns], when the damaged chunk's header still said so."""
    resumed_at: int | None = None
    """Offset where reading resumed after the damage [bytes]; ``None`` when reading stopped there."""


@dataclass
class ScanResult:
    """Every record that could be read from one MCAP file."""

    file_size: int
    """Size of the file [bytes]."""
    schemas: dict[int, Any] = field(default_factory=dict)
    """``mcap.records.Schema`` by id."""
    channels: dict[int, Any] = field(default_factory=dict)
    """``mcap.records.Channel`` by id."""
    messages: list[Any] = field(default_factory=list)
    """``mcap.records.Message`` records in file order."""
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    """Metadata records by name (first occurrence)."""
    damage: list[DamageReport] = field(default_factory=list)
    """Where the file was damaged; empty for an intact file."""
    complete: bool = False
    """Whether the footer was reached."""


def _u64(data: bytes, pos: int) -> int:
    """Read a little-endian uint64."""
    return struct.unpack_from("<Q", data, pos)[0]


def _chunk_header(payload: bytes) -> tuple[int, int, int, int, str, int, int]:
    """Parse a chunk header: start, end, uncompressed size, crc, compression, records offset, records length."""
    start, end, usize, crc, clen = struct.unpack_from("<QQQII", payload, 0)
    comp = payload[32 : 32 + clen].decode()
    (rlen,) = struct.unpack_from("<Q", payload, 32 + clen)
    return start, end, usize, crc, comp, 40 + clen, rlen


def _decompress(comp: str, data: bytes, usize: int, partial: bool) -> bytes:
    """Decompress chunk records; with ``partial``, return the decodable prefix of a cut stream."""
    if comp == "":
        return data
    if comp == "zstd":
        import zstandard

        if partial:
            return zstandard.ZstdDecompressor().decompressobj().decompress(data)
        return zstandard.ZstdDecompressor().decompress(data, max_output_size=usize)
    if comp == "lz4":
        import lz4.frame

        if partial:
            return lz4.frame.LZ4FrameDecompressor().decompress(data)
        return lz4.frame.decompress(data)
    raise ValueError(f"unknown chunk compression {comp!r}")


def _inner_records(data: bytes, out: ScanResult) -> int:
    """Parse the records inside a decompressed chunk; return how many complete messages were added."""
    from mcap.data_stream import ReadDataStream
    from mcap.records import Channel, Message, Schema

    pos, n = 0, 0
    while pos + 9 <= len(data):
        op, length = data[pos], _u64(data, pos + 1)
        end = pos + 9 + length
        if end > len(data):
            break
        stream = ReadDataStream(io.BytesIO(data[pos + 9 : end]))
        if op == 0x05:
            out.messages.append(Message.read(stream, length))
            n += 1
        elif op == 0x04:
            ch = Channel.read(stream)
            out.channels.setdefault(ch.id, ch)
        elif op == 0x03:
            sc = Schema.read(stream)
            out.schemas.setdefault(sc.id, sc)
        pos = end
    return n


def _read_chunk(payload: bytes, out: ScanResult) -> None:
    """Decompress and parse a complete chunk, validating its CRC; raise on any inconsistency."""
    _, _, usize, crc, comp, roff, rlen = _chunk_header(payload)
    if roff + rlen != len(payload):
        raise ValueError("chunk records length disagrees with the record length")
    data = _decompress(comp, payload[roff : roff + rlen], usize, partial=False)
    if len(data) != usize:
        raise ValueError(f"decompressed {len(data)} bytes, header says {usize}")
    if crc != 0 and zlib.crc32(data) != crc:
        raise ValueError(f"CRC mismatch (stored {crc:#010x}, computed {zlib.crc32(data):#010x})")
    tmp = ScanResult(file_size=0)
    _inner_records(data, tmp)  # parse fully before committing, so a bad chunk adds nothing
    out.messages.extend(tmp.messages)
    for k, v in tmp.channels.items():
        out.channels.setdefault(k, v)
    for k, v in tmp.schemas.items():
        out.schemas.setdefault(k, v)


def _read_top_record(op: int, payload: bytes, out: ScanResult) -> None:
    """Parse a top-level (non-chunk) record into ``out``."""
    from mcap.data_stream import ReadDataStream
    from mcap.records import Channel, Message, Metadata, Schema

    stream = ReadDataStream(io.BytesIO(payload))
    if op == 0x03:
        sc = Schema.read(stream)
        out.schemas.setdefault(sc.id, sc)
    elif op == 0x04:
        ch = Channel.read(stream)
        out.channels.setdefault(ch.id, ch)
    elif op == 0x05:
        out.messages.append(Message.read(stream, len(payload)))
    elif op == 0x0C:
        md = Metadata.read(stream)
        out.metadata.setdefault(md.name, dict(md.metadata))


def _salvage_cut_chunk(payload: bytes, pos: int, out: ScanResult) -> str:
    """Recover the complete messages at the start of a chunk cut by the end of the file."""
    try:
        start, end, usize, _, comp, roff, _ = _chunk_header(payload)
        data = _decompress(comp, payload[roff:], usize, partial=True)
        n = _inner_records(data, out)
    except Exception as exc:  # any parse failure of a cut chunk means nothing is salvageable
        return f"nothing salvaged from the cut chunk ({type(exc).__name__})"
    return f"salvaged {n} messages from the cut chunk (chunk covered log_time {start}..{end} ns)"


def _resync(data: bytes, start: int) -> int | None:
    """Return the offset of the next chunk after ``start`` that decodes with a valid CRC, or ``None``."""
    pos, tried = start, 0
    while tried < _MAX_RESYNC_CANDIDATES:
        pos = data.find(b"\x06", pos)
        if pos < 0 or pos + 9 > len(data):
            return None
        tried += 1
        length = _u64(data, pos + 1)
        if 40 <= length <= len(data) - pos - 9:
            try:
                _read_chunk(data[pos + 9 : pos + 9 + length], ScanResult(file_size=0))
                return pos
            except Exception:  # not a chunk boundary; keep searching
                pass
        pos += 1
    return None


def _time_range(payload: bytes) -> tuple[int, int] | None:
    """Return the log-time range of a chunk header, or ``None`` when the header itself is unreadable."""
    try:
        start, end = struct.unpack_from("<QQ", payload, 0)
    except struct.error:
        return None
    return (start, end) if start <= end else None


def scan_mcap(path: str | Path) -> ScanResult:
    """Read every recoverable record of an MCAP file and report the damage.

    Args:
        path: MCAP file.

    Returns:
        The readable schemas, channels, messages and metadata, with one :class:`DamageReport` per damaged place.

    Raises:
        LogFormatError: If the file does not start with the MCAP magic (not an MCAP file, or cut within 8 bytes).
    """
    from gmloco.deploy.logs.errors import LogFormatError

    data = Path(path).read_bytes()
    out = ScanResult(file_size=len(data))
    if data[:8] != _MAGIC:
        raise LogFormatError(
            f"{path}: not an MCAP file (first bytes {data[:8]!r}, expected {_MAGIC!r}); "
            f"{'the file is empty or was cut within its first 8 bytes' if len(data) < 8 else 'wrong file type?'}"
        )
    pos = 8
    while True:
        if pos >= len(data):
            out.damage.append(DamageReport("no_footer", pos, f"file ends at byte {pos} without a footer"))
            break
        if pos + 9 > len(data):
            out.damage.append(DamageReport("truncated", pos, f"file ends inside a record header at byte {pos}"))
            break
        op, length = data[pos], _u64(data, pos + 1)
        end = pos + 9 + length
        name = _OP_NAMES.get(op)
        if name is None or end > len(data):
            nxt = _resync(data, pos + 1)
            if nxt is None and name is not None:
                payload = data[pos + 9 :]
                salvage = _salvage_cut_chunk(payload, pos, out) if op == 0x06 else "nothing salvaged"
                detail = (
                    f"file ends inside a {name} record at byte {pos} (record declares {length} bytes, "
                    f"{len(payload)} present); {salvage}"
                )
                rng = _time_range(payload) if op == 0x06 else None
                out.damage.append(DamageReport("truncated", pos, detail, rng))
                break
            what = f"opcode {op:#04x}" if name is None else f"{name} record with length {length}"
            if nxt is None:
                out.damage.append(
                    DamageReport(
                        "corrupted_record",
                        pos,
                        f"unreadable {what} at byte {pos}; no readable chunk after it, stopped reading",
                    )
                )
                break
            out.damage.append(
                DamageReport(
                    "corrupted_record",
                    pos,
                    f"unreadable {what} at byte {pos}; skipped {nxt - pos} bytes to the next readable chunk",
                    None,
                    nxt,
                )
            )
            pos = nxt
            continue
        payload = data[pos + 9 : end]
        try:
            if op == 0x06:
                _read_chunk(payload, out)
            elif op == 0x02:
                out.complete = data[end : end + 8] == _MAGIC
                if not out.complete:
                    out.damage.append(
                        DamageReport(
                            "truncated",
                            end,
                            f"file ends inside the closing magic at byte {end}; all records before it were read",
                        )
                    )
                break
            else:
                _read_top_record(op, payload, out)
        except Exception as exc:
            rng = _time_range(payload) if op == 0x06 else None
            kind = "corrupted_chunk" if op == 0x06 else "corrupted_record"
            out.damage.append(DamageReport(kind, pos, f"{name} at byte {pos} unreadable ({exc}); skipped", rng, end))
        pos = end
    return out
