# SPDX-License-Identifier: Apache-2.0
"""Append-only study records: one CSV row and one JSONL series per (variant, trial, model), resumable."""

from __future__ import annotations

import csv
import gzip
import json
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["StudyRecords"]

_GZIP_MAGIC = b"\x1f\x8b\x08"
"""Start of a gzip member (ID1, ID2, deflate)."""


class StudyRecords:
    """Append-only ``trials.csv`` + ``grf.jsonl.gz`` in one directory; a key present in both is done.

    The series file is gzip-compressed JSON lines (one gzip member per record: a member torn by a crash is skipped
    and the records before and after it are kept). Directories written before the compression keep their plain ``grf.jsonl``,
    which is read and appended to as it is.
    """

    def __init__(self, out_dir: str | Path) -> None:
        """Open (or create) the records under ``out_dir``."""
        self.dir = Path(out_dir)
        self.dir.mkdir(parents=True, exist_ok=True)
        self.csv_path = self.dir / "trials.csv"
        plain = self.dir / "grf.jsonl"
        self.series_path = plain if plain.exists() else self.dir / "grf.jsonl.gz"

    @staticmethod
    def key(variant: str, trial: int, model: str) -> tuple[str, int, str]:
        """Return the record key."""
        return (variant, int(trial), model)

    def rows(self) -> list[dict[str, Any]]:
        """Return all CSV rows (numbers parsed), only those whose series line also exists."""
        if not self.csv_path.exists():
            return []
        done = {self.key(s["variant"], s["trial"], s["model"]) for s in self.series()}
        with self.csv_path.open() as f:
            rows = [{k: _parse(v) for k, v in r.items()} for r in csv.DictReader(f)]
        return [r for r in rows if self.key(r["variant"], r["trial"], r["model"]) in done]

    def series(self) -> list[dict[str, Any]]:
        """Return all complete JSONL series records (a torn last line or gzip member is ignored)."""
        if not self.series_path.exists():
            return []
        out = []
        for line in _lines(self.series_path):
            try:
                out.append(json.loads(line))
            except json.JSONDecodeError:
                continue
        return out

    def done(self) -> set[tuple[str, int, str]]:
        """Return the keys with both a row and a series."""
        return {self.key(r["variant"], r["trial"], r["model"]) for r in self.rows()}

    def append(self, row: dict[str, Any], series: dict[str, np.ndarray]) -> None:
        """Append one series line, then one CSV row (the row marks the record complete)."""
        rec = {"variant": row["variant"], "trial": int(row["trial"]), "model": row["model"]}
        rec.update({k: np.round(np.asarray(v, dtype=np.float64), 6).tolist() for k, v in series.items()})
        line = json.dumps(rec) + "\n"
        if self.series_path.suffix == ".gz":
            with gzip.open(self.series_path, "at") as f:
                f.write(line)
        else:
            with self.series_path.open("a") as f:
                f.write(line)
        new = not self.csv_path.exists()
        if not new:
            with self.csv_path.open() as f:
                header = next(csv.reader(f), None)
            if header is not None and header != list(row):
                raise ValueError(f"{self.csv_path}: columns {header} differ from the new row's {list(row)}")
        with self.csv_path.open("a", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(row))
            if new:
                writer.writeheader()
            writer.writerow(row)


def _lines(path: Path) -> Iterator[str]:
    """Yield the lines of a plain or gzip JSONL file; damaged gzip members are skipped, the others kept."""
    if path.suffix != ".gz":
        yield from path.read_text().splitlines()
        return
    for member in _gzip_members(path.read_bytes()):
        yield from member.splitlines()


def _gzip_members(data: bytes) -> Iterator[str]:
    """Decode each complete gzip member of ``data``; after a torn or corrupt one, resume at the next gzip header.

    A crash mid-append leaves a truncated member; later appends add whole members after it, which stay readable.
    """
    pos = 0
    while pos < len(data):
        d = zlib.decompressobj(wbits=31)
        try:
            text = d.decompress(data[pos:])
        except zlib.error:
            text = b""
        if d.eof:
            yield text.decode()
            pos = len(data) - len(d.unused_data)
            continue
        nxt = data.find(_GZIP_MAGIC, pos + 1)  # damaged member: skip to the next one, if any
        if nxt < 0:
            return
        pos = nxt


def _parse(value: str) -> Any:
    """Parse a CSV cell into int, float or str."""
    for cast in (int, float):
        try:
            return cast(value)
        except ValueError:
            continue
    return value
