# SPDX-License-Identifier: Apache-2.0
"""Append-only study records: one CSV row and one JSONL series per (variant, trial, model), resumable."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["StudyRecords"]


class StudyRecords:
    """Append-only ``trials.csv`` + ``grf.jsonl`` in one directory; a key present in both is done."""

    def __init__(self, out_dir: str | Path) -> None:
        """Open (or create) the records under ``out_dir``."""
        self.dir = Path(out_dir)
        self.dir.mkdir(parents=True, exist_ok=True)
        self.csv_path = self.dir / "trials.csv"
        self.series_path = self.dir / "grf.jsonl"

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
        """Return all complete JSONL series records (a torn last line is ignored)."""
        if not self.series_path.exists():
            return []
        out = []
        for line in self.series_path.read_text().splitlines():
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
        with self.series_path.open("a") as f:
            f.write(json.dumps(rec) + "\n")
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


def _parse(value: str) -> Any:
    """Parse a CSV cell into int, float or str."""
    for cast in (int, float):
        try:
            return cast(value)
        except ValueError:
            continue
    return value
