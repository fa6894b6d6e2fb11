# SPDX-License-Identifier: Apache-2.0
"""Study records: compressed series round trip, torn tails, legacy plain directories."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np

from gmloco.eval.studies.study_io import StudyRecords


def _append(rec: StudyRecords, trial: int) -> None:
    row = {"variant": "forward", "trial": trial, "model": "mpm", "travel": 0.1 * trial}
    rec.append(row, {"grf": np.full((3, 3), float(trial)), "time": np.arange(3) * 0.01})


def test_new_directory_writes_gzip_and_reads_it_back(tmp_path: Path) -> None:
    """A fresh directory stores the series gzip-compressed; rows, series and done keys survive a reopen."""
    rec = StudyRecords(tmp_path)
    for t in range(3):
        _append(rec, t)
    assert (tmp_path / "grf.jsonl.gz").exists() and not (tmp_path / "grf.jsonl").exists()
    again = StudyRecords(tmp_path)
    assert [s["grf"][0][0] for s in again.series()] == [0.0, 1.0, 2.0]
    assert again.done() == {("forward", t, "mpm") for t in range(3)}


def test_torn_gzip_tail_keeps_the_complete_records(tmp_path: Path) -> None:
    """A record cut off mid-write (truncated last member) is dropped, the ones before it are kept, not resumed."""
    rec = StudyRecords(tmp_path)
    for t in range(2):
        _append(rec, t)
    path = tmp_path / "grf.jsonl.gz"
    whole = path.read_bytes()
    _append(rec, 2)
    path.write_bytes(path.read_bytes()[: len(whole) + 10])  # the third member's header only
    assert [s["trial"] for s in StudyRecords(tmp_path).series()] == [0, 1]
    assert StudyRecords(tmp_path).done() == {("forward", 0, "mpm"), ("forward", 1, "mpm")}


def test_legacy_plain_directory_is_read_and_extended_in_place(tmp_path: Path) -> None:
    """A directory holding a plain grf.jsonl (written before compression) keeps appending to it."""
    rec = StudyRecords(tmp_path)
    _append(rec, 0)
    with gzip.open(tmp_path / "grf.jsonl.gz", "rt") as f:
        (tmp_path / "grf.jsonl").write_text(f.read())
    (tmp_path / "grf.jsonl.gz").unlink()
    legacy = StudyRecords(tmp_path)
    _append(legacy, 1)
    assert not (tmp_path / "grf.jsonl.gz").exists()
    assert [s["trial"] for s in StudyRecords(tmp_path).series()] == [0, 1]


def test_records_appended_after_a_torn_member_stay_readable(tmp_path: Path) -> None:
    """Resume after a crash mid-append: the torn record is lost, the ones before and after it are read."""
    rec = StudyRecords(tmp_path)
    _append(rec, 0)
    path = tmp_path / "grf.jsonl.gz"
    whole = path.read_bytes()
    _append(rec, 1)
    path.write_bytes(path.read_bytes()[: len(whole) + 25])  # record 1 torn mid-member
    _append(StudyRecords(tmp_path), 2)
    assert [s["trial"] for s in StudyRecords(tmp_path).series()] == [0, 2]
