# SPDX-License-Identifier: Apache-2.0
"""Damaged files: truncated and corrupted logs are read up to (or around) the damage, with a warning."""

from __future__ import annotations

import re
import shutil
import struct
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gmloco.deploy.logs import LogDamageWarning, LogFormatError, read_log
from gmloco.deploy.logs.mcap_scan import scan_mcap


def _cut(src: Path, dst: Path, n: int) -> Path:
    """Copy the first ``n`` bytes of ``src`` to ``dst``."""
    dst.write_bytes(src.read_bytes()[:n])
    return dst


def _chunk_offsets(path: Path) -> list[int]:
    """Byte offsets of the top-level chunk records (opcode 0x06) of an intact file."""
    data, pos, out = path.read_bytes(), 8, []
    while pos + 9 <= len(data):
        op, length = data[pos], struct.unpack_from("<Q", data, pos + 1)[0]
        if op == 0x06:
            out.append(pos)
        if op == 0x02:
            break
        pos += 9 + length
    return out


@pytest.mark.parametrize("fraction", [0.25, 0.5, 0.75, 0.95])
def test_truncated_file_reads_prefix_with_warning(tmp_path: Path, synthetic_log: Path, synthetic: Any,
                                                  fraction: float) -> None:  # fmt: skip
    """A file cut at a fraction of its size yields an exact prefix of the data and names byte and time."""
    size = synthetic_log.stat().st_size
    cut = _cut(synthetic_log, tmp_path / "cut.mcap", int(fraction * size))
    with pytest.warns(LogDamageWarning, match=r"damaged at byte \d+ .*data read up to t = ") as rec:
        log = read_log(cut)
    assert any(re.search(r"file ends inside a Chunk record at byte \d+", str(w.message)) for w in rec)
    t, q = log.signal("lowstate.q")
    n = len(t)
    assert 0 < n < len(synthetic.t)
    np.testing.assert_array_equal(q, synthetic.q[:n])  # exactly the prefix, nothing invented
    assert log.run_end is None  # the end record was lost with the tail


def test_more_bytes_never_read_less(tmp_path: Path, synthetic_log: Path) -> None:
    """The number of samples read grows monotonically with the cut position (salvage of cut chunks)."""
    size = synthetic_log.stat().st_size
    counts = []
    for n in np.linspace(0.3 * size, size - 1, 7).astype(int):
        with pytest.warns(LogDamageWarning):
            counts.append(len(read_log(_cut(synthetic_log, tmp_path / f"c{n}.mcap", n)).signal("lowstate.q")[0]))
    assert counts == sorted(counts)


def test_cut_in_summary_loses_no_data(tmp_path: Path, synthetic_log: Path, synthetic: Any) -> None:
    """A cut after the data section (in the summary/footer) still yields every message."""
    cut = _cut(synthetic_log, tmp_path / "cut.mcap", synthetic_log.stat().st_size - 30)
    with pytest.warns(LogDamageWarning):
        log = read_log(cut)
    assert len(log.signal("lowstate.q")[0]) == len(synthetic.t)


@pytest.mark.parametrize("n", [0, 5])
def test_cut_inside_magic_is_refused(tmp_path: Path, synthetic_log: Path, n: int) -> None:
    """A file shorter than the MCAP magic is not a log: a clear error, not an empty result."""
    with pytest.raises(LogFormatError, match="not an MCAP file"):
        read_log(_cut(synthetic_log, tmp_path / "tiny.mcap", n))


def test_cut_before_metadata_is_refused(tmp_path: Path, synthetic_log: Path) -> None:
    """A file cut before the run metadata says so."""
    with pytest.raises(LogFormatError, match=r"no 'gmloco.run' metadata record.*damaged at byte"):
        read_log(_cut(synthetic_log, tmp_path / "head.mcap", 40))


def test_corrupted_chunk_is_skipped_and_reading_continues(tmp_path: Path, synthetic_log: Path, synthetic: Any) -> None:
    """Garbage inside one chunk loses that chunk only; later chunks are read, the lost time range is named."""
    offsets = _chunk_offsets(synthetic_log)
    assert len(offsets) >= 4, "fixture should span several chunks"
    data = bytearray(synthetic_log.read_bytes())
    victim = offsets[2]
    data[victim + 80 : victim + 120] = b"\xa5" * 40
    bad = tmp_path / "corrupt.mcap"
    bad.write_bytes(bytes(data))
    with pytest.warns(LogDamageWarning, match=rf"damaged at byte {victim} .*corrupted_chunk.*lost log_time"):
        log = read_log(bad)
    t, q = log.signal("lowstate.q")
    assert 0 < len(t) < len(synthetic.t)
    assert t[-1] == pytest.approx(synthetic.t[-1])  # data after the damage were read
    idx = np.rint(t * 200).astype(int)  # 200 Hz synthetic: sample index from time
    np.testing.assert_array_equal(q, synthetic.q[idx])
    assert np.any(np.diff(idx) > 1)  # a gap where the chunk was lost


def test_corrupted_record_length_resyncs(tmp_path: Path, synthetic_log: Path, synthetic: Any) -> None:
    """A destroyed record length (framing lost) is skipped by resyncing on the next valid chunk."""
    offsets = _chunk_offsets(synthetic_log)
    data = bytearray(synthetic_log.read_bytes())
    data[offsets[1] + 1 : offsets[1] + 9] = struct.pack("<Q", 2**60)
    bad = tmp_path / "framing.mcap"
    bad.write_bytes(bytes(data))
    with pytest.warns(LogDamageWarning, match=rf"byte {offsets[1]} .*skipped \d+ bytes to the next readable chunk"):
        log = read_log(bad)
    assert log.signal("lowstate.q")[0][-1] == pytest.approx(synthetic.t[-1])


def test_scan_of_intact_file_reports_no_damage(synthetic_log: Path) -> None:
    """The scanner reaches the footer of an intact file."""
    scan = scan_mcap(synthetic_log)
    assert scan.complete and scan.damage == []


def test_reader_never_modifies_input(tmp_path: Path, synthetic_log: Path) -> None:
    """Reading (even a damaged file) leaves the bytes untouched."""
    cut = _cut(synthetic_log, tmp_path / "cut.mcap", synthetic_log.stat().st_size // 2)
    before = cut.read_bytes()
    with pytest.warns(LogDamageWarning):
        read_log(cut)
    assert cut.read_bytes() == before
    shutil.rmtree(tmp_path, ignore_errors=True)
