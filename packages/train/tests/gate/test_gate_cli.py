# SPDX-License-Identifier: Apache-2.0
"""``python -m gmloco.train.gate``: bad input exits 2; a CPU-sized run of committed policies writes every key."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pytest

from gmloco.train.gate.__main__ import _cfg, _parse, main

REPO = Path(__file__).resolve().parents[4]
"""Repository root (the committed artifacts)."""
KEYS = ("success_pct", "vel_error_mps", "yaw_rate_ratio", "heading_drift_deg", "circle_dtw_m", "swing_apex_cm",
        "eta_r2_heldout", "gpu_minutes")  # fmt: skip
"""The issue's keys."""
OPTIONS = {"-h", "--help", "--policy", "--out", "--episodes", "--seconds", "--num-envs", "--materials", "--speeds",
           "--yaw-rates", "--held-out-grid", "--contact-model", "--rft-extensions", "--parts", "--floor-depth",
           "--device", "--seed"}  # fmt: skip
"""The option strings of the command line as the recorded commands know it (hand-written argparse, 15 flags)."""


def _recorded_commands() -> list[list[str]]:
    """The gate's arguments in the commands written down in the READMEs of ``results/`` and ``artifacts/``."""
    found = []
    for readme in [*REPO.glob("results/**/README.md"), *REPO.glob("artifacts/**/README.md")]:
        found += re.findall(r"`python -m gmloco\.train\.gate (--[^`]+)`", readme.read_text())
    return [shlex.split(args) for args in found]


def test_help_lists_the_recorded_options(capsys: pytest.CaptureFixture[str]) -> None:
    """The generated flags and the command line's own give exactly the option strings the commands were written with."""
    with pytest.raises(SystemExit) as stop:
        _parse(["--help"])
    assert stop.value.code == 0
    assert set(re.findall(r"(?<![\w-])-{1,2}[a-z][\w-]*", capsys.readouterr().out.split("options:")[1])) == OPTIONS


def test_recorded_commands_still_parse(tmp_path: Path) -> None:
    """Every gate command in the READMEs parses (``--out`` added where it was left out)."""
    commands = _recorded_commands()
    assert len(commands) >= 3
    for argv in commands:
        args = _parse([*argv, "--out", str(tmp_path / "g.json")] if "--out" not in argv else argv)
        assert args.episodes >= 1 and args.speeds


def test_the_small_scale_command_fills_the_gate_config() -> None:
    """The recorded small-scale command sets its fields; lists are comma-separated words, parts in summary order."""
    argv = ["--policy", "artifacts/gm_loco_student_td", "--out", "g.json", "--episodes", "2", "--num-envs", "4",
            "--seconds", "10", "--materials", "dry_sand,poppy_seed,basalt", "--speeds", "1.0,1.5,2.0,2.5",
            "--yaw-rates", "0.5", "--held-out-grid", "2,1", "--parts", "yaw,success", "--seed", "3"]  # fmt: skip
    cfg = _cfg(_parse(argv))
    assert (cfg.policy_dir, cfg.out_path, cfg.repeats, cfg.num_envs, cfg.duration_s) == (argv[1], "g.json", 2, 4, 10.0)
    assert cfg.materials == ("dry_sand", "poppy_seed", "basalt") and cfg.speeds == (1.0, 1.5, 2.0, 2.5)
    assert (cfg.yaw_rates, cfg.held_out_grid, cfg.parts, cfg.seed) == ((0.5,), (2, 1), ("success", "yaw"), 3)


@pytest.mark.parametrize(
    ("flag", "value", "message"),
    [
        ("--episodes", "0", "--episodes 0 must be >= 1"),
        ("--episodes", "two", "argument --episodes: invalid int value: 'two'"),
        ("--num-envs", "0", "--num-envs 0 must be >= 1"),
        ("--seconds", "-1", "--seconds -1.0 must be > 0"),
        ("--speeds", "1,-0.5", "--speeds -0.5 must be > 0"),
        ("--speeds", "1,fast", "argument --speeds: 'fast': expected a float"),
        ("--materials", ",", "argument --materials: ',': expected one or more values"),
        ("--held-out-grid", "3", "argument --held-out-grid: '3': expected 2 values separated by ','"),
        ("--held-out-grid", "0,3", "--held-out-grid 0 must be >= 1"),
    ],
)
def test_malformed_or_out_of_range_flags_exit_2(
    flag: str, value: str, message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """A malformed or out-of-range value is a usage error (exit code 2) naming the flag."""
    with pytest.raises(SystemExit) as stop:
        main(["--policy", "unused", "--out", "unused.json", flag, value])
    assert stop.value.code == 2
    assert message in capsys.readouterr().err


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
