# SPDX-License-Identifier: Apache-2.0
"""``python -m gmloco.train.gate``: bad input exits 2; a CPU-sized run of committed policies writes every key."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gmloco.train.gate.__main__ import main

REPO = Path(__file__).resolve().parents[4]
"""Repository root (the committed artifacts)."""
KEYS = ("success_pct", "vel_error_mps", "yaw_rate_ratio", "heading_drift_deg", "circle_dtw_m", "swing_apex_cm",
        "eta_r2_heldout", "gpu_minutes")  # fmt: skip
"""The issue's keys."""


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--policy", "no/such/run"], "no such folder"),
        (["--policy", "{tmp}"], "neither train_cfg.json nor a summary.json"),
        (["--policy", "artifacts/gm_loco_student_td", "--materials", "sand"], "unknown ['sand']"),
        (["--policy", "artifacts/gm_loco_student_td", "--yaw-rates", "0,1"], "0 has no achieved/commanded ratio"),
        (["--policy", "artifacts/gm_loco_student_td", "--held-out-grid", "1,1"], "at least two points"),
    ],
)
def test_bad_input_exits_2(
    argv: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each bad input is refused before any env is built, with a message saying what was wrong."""
    monkeypatch.chdir(REPO)
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main([*argv, "--out", str(tmp_path / "gate.json")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "gate.json").exists()


@pytest.mark.slow
@pytest.mark.parametrize("run", ["gm_loco_student_td", "gm_loco_teacher_yaw", "ppo_rft3d"])
def test_cpu_sized_gate_writes_every_key(run: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """2 episodes per cell, 4 envs, 2 s, one material pair and one command each: all keys, a pass map, GPU minutes."""
    monkeypatch.chdir(REPO)
    out = tmp_path / "summary.json"
    argv = ["--policy", f"artifacts/{run}", "--out", str(out), "--episodes", "2", "--num-envs", "4", "--seconds", "2",
            "--materials", "basalt,poppy_seed", "--speeds", "1.0", "--yaw-rates", "0.5", "--held-out-grid", "2,1"]  # fmt: skip
    assert main(argv) == 0
    summary = json.loads(out.read_text())
    assert set(KEYS) <= set(summary) and set(summary["pass"]) == {*KEYS, "all"}
    assert set(summary["success_pct"]) == {"basalt", "poppy_seed"}
    assert 0.0 <= summary["success_pct"]["basalt"]["1"] <= 100.0
    assert summary["gpu_minutes"] is not None and summary["gpu_minutes"] > 0
    assert (summary["eta_r2_heldout"] is None) == (run == "ppo_rft3d")
    assert summary["setup"]["yaw_command"] == ("yaw_target" if run == "gm_loco_teacher_yaw" else "heading_envs")


def test_floor_depth_puts_a_hard_floor_under_the_feet() -> None:
    """--floor-depth D enables the feet's floor D m down; without it the gate keeps the 30 cm bed with no foot floor."""
    from gmloco.train.gate.__main__ import _cfg, _parse

    base = ["--policy", "unused", "--out", "unused.json", "--contact-model", "rft3d"]
    deep = _cfg(_parse(base)).floor
    floor = _cfg(_parse([*base, "--floor-depth", "0.025"])).floor
    assert not deep.enabled and deep.depth_range == (0.3, 0.3)
    assert floor.enabled and floor.depth_range == (0.025, 0.025) and not floor.curriculum


def test_floor_depth_must_be_positive(capsys: pytest.CaptureFixture[str]) -> None:
    """A floor at or above the surface is refused with exit 2."""
    from gmloco.train.gate.__main__ import _parse

    with pytest.raises(SystemExit) as exc:
        _parse(["--policy", "unused", "--out", "unused.json", "--floor-depth", "0"])
    assert exc.value.code == 2 and "expected a number > 0" in capsys.readouterr().err
