# SPDX-License-Identifier: Apache-2.0
"""Atomic writes: all or nothing, nothing left beside the target."""

from __future__ import annotations

import json
from pathlib import Path
from typing import IO

import pytest

from gmloco.deploy.atomic_io import atomic_write, atomic_write_json


def test_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path: Path) -> None:
    """An error inside ``write`` leaves the previous content and no temporary file."""
    target = atomic_write_json(tmp_path / "sub" / "a.json", {"x": 1})
    assert json.loads(target.read_text()) == {"x": 1} and oct(target.stat().st_mode & 0o777) == "0o644"

    def fail(fh: IO[bytes]) -> None:
        fh.write(b"half")
        raise RuntimeError("killed")

    with pytest.raises(RuntimeError, match="killed"):
        atomic_write(target, fail)
    assert json.loads(target.read_text()) == {"x": 1}
    assert [p.name for p in target.parent.iterdir()] == ["a.json"]


def test_strict_json_refuses_nan_and_adds_the_newline(tmp_path: Path) -> None:
    """``allow_nan=False`` raises on NaN without writing; ``newline`` ends the file with one."""
    path = tmp_path / "b.json"
    with pytest.raises(ValueError):
        atomic_write_json(path, {"x": float("nan")}, allow_nan=False)
    assert not path.exists()
    assert atomic_write_json(path, [1], newline=True).read_text().endswith("]\n")
