# SPDX-License-Identifier: Apache-2.0
"""Episode rows: reading a damaged episodes.jsonl, and window exits that came with a fall."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gmloco.eval.metrics.episodes import exit_in_fall


def test_episodes_are_read_up_to_a_partial_last_line(tmp_path: Path) -> None:
    """A run killed mid-write leaves half a line: skipped (and cut off with repair); damage earlier is an error."""
    from gmloco.eval.metrics.episodes import read_episodes

    path = tmp_path / "episodes.jsonl"
    path.write_text(json.dumps({"key": "a"}) + "\n" + json.dumps({"key": "b"}) + "\n" + '{"key": "c", "succ')
    assert [r["key"] for r in read_episodes(path)] == ["a", "b"]
    assert path.read_text().count("\n") == 2  # untouched without repair
    assert [r["key"] for r in read_episodes(path, repair=True)] == ["a", "b"]
    assert path.read_text() == json.dumps({"key": "a"}) + "\n" + json.dumps({"key": "b"}) + "\n"
    path.write_text('{"key": "a"}\nnot json\n{"key": "b"}\n')
    with pytest.raises(ValueError, match=r"episodes\.jsonl:2: not an episode record"):
        read_episodes(path)


def test_an_exit_shortly_before_a_fall_came_with_the_fall() -> None:
    """An early exit 0.3 s before a tilt or a base-height fall is part of the fall.

    One 1 s before, one before a timeout, or none is not.
    """
    row = {"window_exit_early": True, "window_exit_s": 2.7, "alive_s": 3.0, "reason": "tilt", "success": False}
    assert exit_in_fall(row) and exit_in_fall(row | {"reason": "base_height"})
    assert not exit_in_fall(row | {"window_exit_s": 2.0})
    assert not exit_in_fall(row | {"reason": "timeout", "alive_s": 10.0, "window_exit_s": 9.5})
    assert not exit_in_fall(row | {"reason": "success"}) and not exit_in_fall(row | {"window_exit_early": False})
    assert not exit_in_fall({"window_exit_early": True, "reason": "tilt"})  # no times recorded
