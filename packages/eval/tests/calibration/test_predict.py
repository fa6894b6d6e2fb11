# SPDX-License-Identifier: Apache-2.0
"""Predicted against MPM success from small synthetic gate summaries and MPM speed tables."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import pytest

from gmloco.eval.calibration.predict import main

POLICY = "gm_loco_student_td"
"""A policy with MPM speed rows."""
MPM_ROWS = [
    {"policy": POLICY, "terrain": "dry_sand", "scenario": "straight", "v=1 m/s": 76.0, "v=1.5 m/s": 36.0,
     "v=2 m/s": 0.0},
    {"policy": POLICY, "terrain": "dry_sand", "scenario": "circle", "v=1 m/s": 0.0, "v=1.5 m/s": 0.0, "v=2 m/s": 0.0},
    {"policy": POLICY, "terrain": "poppy_seed", "scenario": "straight", "v=1 m/s": 0.0, "v=1.5 m/s": 0.0,
     "v=2 m/s": 0.0},
]  # fmt: skip
"""MPM success [%] by speed: the straight rows are compared, the circle row is not."""


def _gate(
    tmp: Path,
    model: str,
    success: dict[str, dict[str, float]],
    policy: str = POLICY,
    survival: dict[str, dict[str, float]] | None = None,
) -> str:
    """Write a gate summary of ``policy`` in ``model``: success [%] by MPM's rule, and survival (default: the same)."""
    path = tmp / f"gate_{policy}_{model}.json"
    body = {
        "policy": f"artifacts/{policy}",
        "success_pct": success if survival is None else survival,
        "success_course_pct": success,
        "setup": {"contact_model": model},
    }
    path.write_text(json.dumps(body))
    return str(path)


def _folder(path: Path) -> Path:
    """Make and return a folder."""
    path.mkdir()
    return path


def _mpm(tmp: Path, rows: list[dict[str, Any]] = MPM_ROWS) -> str:
    """Write an MPM summary holding ``speed_rows``."""
    path = tmp / "mpm_summary.json"
    path.write_text(json.dumps({"speed_rows": rows, "rows": []}))
    return str(path)


def _run(tmp: Path, gates: list[str], mpm: str, *extra: str) -> tuple[int, dict[str, Any]]:
    """Run the command; return (exit code, written JSON or {})."""
    out = tmp / "out" / "predicted.json"
    code = main(["--gate", *gates, "--mpm", mpm, "--out", str(out), *extra])
    return code, json.loads(out.read_text()) if out.is_file() else {}


def test_numbers_are_carried_through(tmp_path: Path) -> None:
    """MPM and each model's success per material and speed, difference = predicted - MPM, verdict |diff| <= 15."""
    gates = [
        _gate(tmp_path, "rft3d", {"dry_sand": {"0.5": 100.0, "1": 100.0, "1.5": 100.0}}),
        _gate(tmp_path, "rft3d_calibrated", {"dry_sand": {"0.5": 100.0, "1": 80.0, "1.5": 55.0}}),
    ]
    code, body = _run(tmp_path, gates, _mpm(tmp_path))
    assert code == 0
    dry = body["predicted_vs_mpm_success"][POLICY]["dry_sand"]
    assert list(dry) == ["1", "1.5"]  # 0.5 m/s: no MPM row; 2 m/s: no gate cell
    assert dry["1"]["mpm_success_pct"] == 76.0
    assert dry["1"]["predicted_success_pct"] == {"rft3d": 100.0, "rft3d_calibrated": 80.0}
    assert dry["1"]["difference_points"] == {"rft3d": 24.0, "rft3d_calibrated": 4.0}  # 100 - 76, 80 - 76
    assert dry["1"]["within_15_points"] == {"rft3d": False, "rft3d_calibrated": True}
    assert dry["1.5"]["difference_points"] == {"rft3d": 64.0, "rft3d_calibrated": 19.0}  # 100 - 36, 55 - 36
    assert body["within_15_points"] == {POLICY: {"rft3d": False, "rft3d_calibrated": False}}
    assert body["contact_models"] == ["rft3d", "rft3d_calibrated"] and body["max_points"] == 15.0
    figure = tmp_path / "out" / f"predicted_success_{POLICY}.png"
    assert figure.stat().st_size > 1000 and body["figures"] == [str(figure)]


def test_csv_speed_table_reads_as_the_summary(tmp_path: Path) -> None:
    """results/mpm_eval/tables/table_speeds.csv gives the same comparison as the summary's speed_rows."""
    path = tmp_path / "table_speeds.csv"
    with path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(MPM_ROWS[0]))
        writer.writeheader()
        writer.writerows(MPM_ROWS)
    gates = [_gate(tmp_path, "rft3d_calibrated", {"poppy_seed": {"1": 10.0, "2": 20.0}})]
    code, from_csv = _run(tmp_path, gates, str(path), "--no-figures")
    assert code == 0
    code, from_json = _run(tmp_path, gates, _mpm(tmp_path), "--no-figures")
    assert from_csv["predicted_vs_mpm_success"] == from_json["predicted_vs_mpm_success"]
    cell = from_csv["predicted_vs_mpm_success"][POLICY]["poppy_seed"]["2"]
    assert (cell["difference_points"], cell["within_15_points"]) == (
        {"rft3d_calibrated": 20.0},
        {"rft3d_calibrated": False},
    )


@pytest.mark.parametrize(
    ("case", "message"),
    [
        ("policy", "policy 'ppo_sand' has no MPM straight speed rows"),
        ("material", "materials ['basalt'] of the gate have no MPM straight row"),
        ("speed", "no speed in both the gate and MPM"),
        ("duplicate", "two gate summaries of gm_loco_student_td with contact model 'rft3d' both cover ['dry_sand']"),
        ("no_success", "has no success table: run the gate with --parts success"),
        ("missing", "not found"),
    ],
)
def test_mismatched_input_exits_2(case: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A gate of a policy or material MPM has not judged, or a malformed input, is refused and named; nothing written."""
    dry = {"dry_sand": {"1": 90.0}}
    gates: dict[str, Any] = {  # built lazily: each case writes its own files
        "policy": lambda: [_gate(tmp_path, "rft3d", dry, policy="ppo_sand")],
        "material": lambda: [_gate(tmp_path, "rft3d", {"basalt": {"1": 90.0}})],
        "speed": lambda: [_gate(tmp_path, "rft3d", {"dry_sand": {"0.5": 90.0}})],
        "duplicate": lambda: [_gate(tmp_path, "rft3d", dry), _gate(_folder(tmp_path / "again"), "rft3d", dry)],
        "no_success": lambda: [_gate(tmp_path, "rft3d", {})],
        "missing": lambda: [str(tmp_path / "no_gate.json")],
    }
    code, body = _run(tmp_path, gates[case](), _mpm(tmp_path), "--no-figures")
    assert code == 2 and body == {}
    assert message in capsys.readouterr().err


def test_gates_of_different_materials_merge(tmp_path: Path) -> None:
    """One gate per material (terms fitted per material) reads as one gate of the policy and contact model."""
    dry = _gate(tmp_path, "rft3d_calibrated", {"dry_sand": {"1": 80.0}})
    poppy = _gate(_folder(tmp_path / "poppy"), "rft3d_calibrated", {"poppy_seed": {"1": 10.0}})
    code, body = _run(tmp_path, [dry, poppy], _mpm(tmp_path), "--no-figures")
    assert code == 0
    cells = body["predicted_vs_mpm_success"][POLICY]
    assert cells["dry_sand"]["1"]["predicted_success_pct"] == {"rft3d_calibrated": 80.0}
    assert cells["poppy_seed"]["1"]["difference_points"] == {"rft3d_calibrated": 10.0}


def test_only_judged_materials_lists_the_rest(tmp_path: Path) -> None:
    """With --only-judged-materials a gated material without an MPM row is left out and named, not an error."""
    gates = [_gate(tmp_path, "rft3d", {"dry_sand": {"1": 100.0}, "basalt": {"1": 100.0}})]
    code, _ = _run(tmp_path, gates, _mpm(tmp_path), "--no-figures")
    assert code == 2
    code, body = _run(tmp_path, gates, _mpm(tmp_path), "--no-figures", "--only-judged-materials")
    assert code == 0
    assert list(body["predicted_vs_mpm_success"][POLICY]) == ["dry_sand"]
    assert body["not_judged_on_mpm"] == {POLICY: ["basalt"]}


def test_criterion_picks_the_gate_table(tmp_path: Path) -> None:
    """MPM's course rule by default (success_course_pct); --criterion survival compares falls only (success_pct)."""
    gate = _gate(tmp_path, "rft3d_calibrated", {"dry_sand": {"1": 50.0}}, survival={"dry_sand": {"1": 100.0}})
    code, body = _run(tmp_path, [gate], _mpm(tmp_path), "--no-figures")
    assert code == 0 and body["criterion"] == "course"
    assert body["predicted_vs_mpm_success"][POLICY]["dry_sand"]["1"]["difference_points"] == {"rft3d_calibrated": -26.0}
    code, body = _run(tmp_path, [gate], _mpm(tmp_path), "--no-figures", "--criterion", "survival")
    assert code == 0 and body["criterion"] == "survival"
    assert body["predicted_vs_mpm_success"][POLICY]["dry_sand"]["1"]["difference_points"] == {"rft3d_calibrated": 24.0}


def test_gate_without_the_course_rule_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A gate summary written before the course rule is refused by default and named; survival alone still reads."""
    path = tmp_path / "old_gate.json"
    body = {
        "policy": f"artifacts/{POLICY}",
        "success_pct": {"dry_sand": {"1": 90.0}},
        "setup": {"contact_model": "rft3d"},
    }
    path.write_text(json.dumps(body))
    code, out = _run(tmp_path, [str(path)], _mpm(tmp_path), "--no-figures")
    assert code == 2 and out == {}
    assert "has no success_course_pct" in capsys.readouterr().err
    code, out = _run(tmp_path, [str(path)], _mpm(tmp_path), "--no-figures", "--criterion", "survival")
    assert code == 0 and out["predicted_vs_mpm_success"][POLICY]["dry_sand"]["1"]["mpm_success_pct"] == 76.0
