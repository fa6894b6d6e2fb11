# SPDX-License-Identifier: Apache-2.0
"""The per-cell walk comparison: MPM episodes and gate summaries reduced to falls, unfinished courses, errors."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from gmloco.eval.calibration.predict import main
from gmloco.eval.calibration.walk_gap import gate_walk, mpm_walks

POLICY = "gm_loco_student_td"


def _episode(terrain: str, speed: float, reason: str, vel: float, turn: float, scenario: str = "straight") -> dict:
    """One scored MPM episode row (the fields the comparison reads)."""
    return {"terrain": terrain, "scenario": scenario, "speed": speed, "success": reason == "success",
            "reason": reason, "vel_error": vel, "heading_turn_deg": turn}  # fmt: skip


def _run(folder: Path, rows: list[dict[str, Any]]) -> str:
    """Write an MPM run folder holding ``episodes.jsonl``; return its path."""
    folder.mkdir(parents=True)
    (folder / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    return str(folder)


def test_mpm_walks_by_hand(tmp_path: Path) -> None:
    """Two folders pool per cell: 1 fall, 1 timeout, 2 successes of 4 -> 25 / 25 / 50 %, medians of 4 values."""
    a = _run(tmp_path / "a", [_episode("basalt", 1.0, "tilt", 0.5, 10.0), _episode("basalt", 1.0, "timeout", 0.3, 70.0),
                              _episode("basalt", 1.0, "success", 0.1, 40.0, scenario="circle")])  # fmt: skip
    b = _run(tmp_path / "b", [_episode("basalt", 1.0, "success", 0.2, 30.0), _episode("basalt", 1.0, "success", 0.1, 20.0),
                              _episode("dry_sand", 1.5, "base_height", 0.9, 5.0)])  # fmt: skip
    walks = mpm_walks([a, b])
    assert walks["basalt"]["1"] == {"episodes": 4, "fell_pct": 25.0, "course_unfinished_pct": 25.0, "success_pct": 50.0,
                                    "vel_error_mps": 0.25, "heading_turn_deg": 25.0}  # fmt: skip
    assert walks["dry_sand"]["1.5"]["fell_pct"] == 100.0
    with pytest.raises(FileNotFoundError, match=r"no episodes\.jsonl"):
        mpm_walks([str(tmp_path / "missing")])


def test_gate_walk_by_hand() -> None:
    """Falls and course_unfinished entries of 8 episodes; a summary before the course rule has no unfinished share."""
    body = {"setup": {"episodes_per_cell": 8}, "success_course_pct": {},
            "failures": {"dry_sand": {"1": ["tilt at 2.80 s", "course_unfinished", "course_unfinished"]}},
            "vel_error_mps": {"dry_sand": {"1": 0.43}}, "heading_drift_deg": {"dry_sand": {"1": 28.5}}}  # fmt: skip
    walk = gate_walk(body, "dry_sand", "1")
    assert walk == {"episodes": 8, "fell_pct": 12.5, "course_unfinished_pct": 25.0, "vel_error_mps": 0.43,
                    "heading_drift_deg": 28.5}  # fmt: skip
    del body["success_course_pct"]
    assert gate_walk(body, "dry_sand", "1")["course_unfinished_pct"] is None  # type: ignore[index]
    assert gate_walk(body, "basalt", "1") is None


def test_prediction_carries_the_walks(tmp_path: Path) -> None:
    """With run folders in the MPM summary every compared cell gets mpm_walk and gate_walk; --no-walks leaves them."""
    run = _run(tmp_path / "run", [_episode("dry_sand", 1.0, "success", 0.16, 36.0)] * 3)
    mpm = tmp_path / "mpm.json"
    mpm.write_text(json.dumps({"runs": {POLICY: {"dirs": [run]}}, "speed_rows": [
        {"policy": POLICY, "terrain": "dry_sand", "scenario": "straight", "v=1 m/s": 76.0}]}))  # fmt: skip
    gate = tmp_path / "gate.json"
    gate.write_text(json.dumps({
        "policy": f"artifacts/{POLICY}", "setup": {"contact_model": "rft3d_calibrated", "episodes_per_cell": 2},
        "success_pct": {"dry_sand": {"1": 50.0}}, "success_course_pct": {"dry_sand": {"1": 0.0}},
        "failures": {"dry_sand": {"1": ["tilt at 1.00 s", "course_unfinished"]}},
        "vel_error_mps": {"dry_sand": {"1": 0.43}}, "heading_drift_deg": {"dry_sand": {"1": 28.5}}}))  # fmt: skip
    out = tmp_path / "out.json"
    assert main(["--gate", str(gate), "--mpm", str(mpm), "--out", str(out), "--no-figures"]) == 0
    cell = json.loads(out.read_text())["predicted_vs_mpm_success"][POLICY]["dry_sand"]["1"]
    assert cell["mpm_walk"]["success_pct"] == 100.0 and cell["mpm_walk"]["vel_error_mps"] == 0.16
    assert cell["gate_walk"]["rft3d_calibrated"]["fell_pct"] == 50.0
    assert cell["gate_walk"]["rft3d_calibrated"]["course_unfinished_pct"] == 50.0
    assert main(["--gate", str(gate), "--mpm", str(mpm), "--out", str(out), "--no-figures", "--no-walks"]) == 0
    assert "mpm_walk" not in json.loads(out.read_text())["predicted_vs_mpm_success"][POLICY]["dry_sand"]["1"]
