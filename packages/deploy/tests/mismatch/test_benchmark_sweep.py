# SPDX-License-Identifier: Apache-2.0
"""The benchmark sweep end to end on a fast subset: one short episode, a three-effect screen."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path
from typing import get_args

import pytest

from gmloco.deploy.mismatch.benchmark import sweep
from gmloco.deploy.mismatch.benchmark.episodes import STRENGTH_TABLES, STRENGTHS
from gmloco.deploy.mismatch.benchmark.policy_motion import MOTIONS
from gmloco.deploy.mismatch.benchmark.sweep import main
from gmloco.deploy.mismatch.benchmark.sweep_cfg import MotionName, StrengthLevel, StrengthTableName, SweepCfg


def test_sweep_subset_writes_rows_summary_manifest_and_a_separate_key(tmp_path: Path) -> None:
    """A 3 s hidden gyro bias is named and fitted; the truth key is written under keys/, apart from the rows."""
    main(
        [
            "--out",
            str(tmp_path),
            "--only",
            "imu.gyro_bias-mid-0",
            "--nulls",
            "0",
            "--duration",
            "3",
            "--workers",
            "1",
            "--effects",
            "imu.gyro_bias,joint.armature,actuator.delay",
        ]
    )
    row = json.loads((tmp_path / "rows" / "imu.gyro_bias-mid-0.json").read_text())
    assert row["verdict"] == "explained" and row["winner"] == "imu.gyro_bias", row
    fit = row["fit"]
    # truth (0.03, -0.02, 0.015) rad/s; the gyro-vs-attitude-rate channel pins it to a few mrad/s
    for lab, truth in (("bias[x]", 0.03), ("bias[y]", -0.02), ("bias[z]", 0.015)):
        assert abs(fit[lab][0] - truth) < 0.004
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["overall"]["top1_mid_macro"] == 1.0
    manifest = json.loads((tmp_path / "manifest.json").read_text())
    inv = manifest["invocations"][-1]
    assert inv["episodes"] == ["imu.gyro_bias-mid-0"] and "commit" in inv["git"]
    assert (tmp_path / "keys" / "imu.gyro_bias-mid-0.json").exists()


def test_seed_offset_and_parts_split_the_lists_into_fresh_interleaved_replicates() -> None:
    """The offset moves every seed and keeps the names; part i/2 takes seed i of each class and every other null."""
    from gmloco.deploy.mismatch.benchmark.episodes import episode_list, sand_episode_list
    from gmloco.deploy.mismatch.benchmark.sweep import _part

    stock, fresh = sand_episode_list(2, 4), sand_episode_list(2, 4, seed_offset=10000)
    assert [e["name"] for e in stock] == [e["name"] for e in fresh]
    assert all(f["seed"] == s["seed"] + 10000 for s, f in zip(stock, fresh, strict=True))
    # the stock single-seed list is unchanged (the sand suite's names and seeds)
    ool = [e for e in sand_episode_list(1, 6) if e["effect"].startswith("ool.")]
    assert [(e["name"], e["seed"]) for e in ool] == [
        ("sand-ool.shank_length-0", 2100),
        ("sand-ool.current_lag-0", 2100),
    ]
    for eps in (fresh, episode_list(2, 4, seed_offset=10000)):
        p0, p1 = _part(eps, "0/2"), _part(eps, "1/2")
        assert len(p0) + len(p1) == len(eps) and {e["name"] for e in p0}.isdisjoint(e["name"] for e in p1)
        classes = {e["effect"] for e in eps if e["effect"] != "none"}
        for part, idx in ((p0, "0"), (p1, "1")):
            eff = [e for e in part if e["effect"] != "none"]
            assert {e["effect"] for e in eff} == classes and all(e["name"].endswith(idx) for e in eff)
            assert sum(e["effect"] == "none" for e in part) == 2


def test_deadline_skips_unstarted_episodes_and_lists_them_as_missing(tmp_path: Path) -> None:
    """Past the deadline no episode starts; nothing is written under rows/ and the summary lists the episodes."""
    main(["--out", str(tmp_path), "--only", "none-", "--nulls", "2", "--workers", "1", "--deadline-s", "-1"])
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["missing"] == ["none-0", "none-1"] and summary["episodes_scored"] == 0
    assert not (tmp_path / "rows").exists()
    inv = json.loads((tmp_path / "manifest.json").read_text())["invocations"][-1]
    assert set(inv["source_sha256"]) == {"mismatch", "contact"} and "mujoco" in inv


def test_strength_table_v4_with_parts_and_resume(tmp_path: Path) -> None:
    """``--strength-table v4 --part 3/8 --resume``: part 3's 12 sand episodes; an existing row is not run again.

    The row already there is scored; the manifest records the table (depth hardening at 150 1/m).
    """
    from gmloco.deploy.mismatch.benchmark.episodes import sand_episode_list
    from gmloco.deploy.mismatch.benchmark.sweep import _part

    args = ["--out", str(tmp_path), "--suite", "sand", "--motion", "composite", "--strength-table", "v4"]
    args += ["--seeds", "2", "--seed-offset", "20000", "--nulls", "64", "--part", "3/8", "--resume"]
    args += ["--workers", "1", "--deadline-s", "-1"]
    part = _part(sand_episode_list(2, 64, seed_offset=20000, motion="composite", table="v4"), "3/8")
    null = next(e for e in part if e["effect"] == "none")
    (tmp_path / "rows").mkdir(parents=True)
    (tmp_path / "rows" / f"{null['name']}.json").write_text(json.dumps({**null, "verdict": "no_mismatch"}))
    main(args)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["episodes_scored"] == 1 and summary["overall"]["null_episodes"] == 1
    assert sorted(summary["missing"]) == sorted(e["name"] for e in part if e is not null)
    inv = json.loads((tmp_path / "manifest.json").read_text())["invocations"][-1]
    assert inv["episodes"] == [e["name"] for e in part] and len(part) == 12
    assert null["name"] not in inv["episodes_run_by_this_invocation"]
    assert inv["strength_table"]["name"] == "v4"
    assert inv["strength_table"]["mid"]["terrain.depth_hardening"] == {"kappa": [150.0]}


OPTIONS = {"-h", "--help", "--out", "--workers", "--seeds", "--nulls", "--duration", "--motion", "--strengths",
           "--strength-table", "--suite", "--keep-before-fall", "--only", "--score-only", "--pool", "--resume",
           "--effects", "--seed-offset", "--part", "--deadline-s"}  # fmt: skip
"""The option strings of the sweep's command line as the recorded commands know it (hand-written, 18 flags)."""
REPO = Path(__file__).resolve().parents[4]
"""Repository root (the recorded manifests)."""


def _recorded_commands() -> list[list[str]]:
    """The sweep's arguments in every command of ``results/**/manifest.json``."""
    found: list[str] = []

    def walk(node: object) -> None:
        if isinstance(node, dict):
            node = list(node.values())
        if isinstance(node, list):
            for child in node:
                walk(child)
        elif isinstance(node, str) and node.startswith(f"python -m {sweep.__name__} "):
            found.append(node.removeprefix(f"python -m {sweep.__name__} "))

    for path in REPO.glob("results/**/manifest.json"):
        walk(json.loads(path.read_text()))
    return [shlex.split(args) for args in found]


def test_help_lists_the_recorded_options(capsys: pytest.CaptureFixture[str]) -> None:
    """The generated flags and ``--out`` give exactly the option strings the commands were written with."""
    with pytest.raises(SystemExit) as stop:
        sweep._parse(["--help"])
    assert stop.value.code == 0
    assert set(re.findall(r"(?<![\w-])-{1,2}[a-z][\w-]*", capsys.readouterr().out.split("options:")[1])) == OPTIONS


def test_recorded_commands_still_parse() -> None:
    """Every sweep command in the results' manifests parses to a config."""
    commands = _recorded_commands()
    assert len(commands) >= 10
    for argv in commands:
        out, cfg = sweep._parse(argv)
        assert out.parts and cfg.workers >= 1


def test_flags_fill_the_sweep_config() -> None:
    """A sand replicate command sets its fields; lists are comma-separated words, switches set True."""
    argv = ["--out", "o", "--seeds", "2", "--seed-offset", "20000", "--part", "3/8", "--resume", "--deadline-s", "300",
            "--suite", "sand", "--motion", "composite", "--strength-table", "v4", "--only", "none-,imu.",
            "--strengths", "low,high", "--effects", "imu.gyro_bias"]  # fmt: skip
    out, cfg = sweep._parse(argv)
    assert out == Path("o")
    assert cfg == SweepCfg(seeds=2, seed_offset=20000, part="3/8", resume=True, deadline_s=300.0, suite="sand",
                           motion="composite", strength_table="v4", only=("none-", "imu."), strengths=("low", "high"),
                           effects=("imu.gyro_bias",))  # fmt: skip
    assert sweep._parse(["--out", "o"])[1] == SweepCfg()


def test_the_closed_choices_match_the_episode_tables() -> None:
    """The motions, strength levels and tables of the config are those the episode lists know."""
    assert set(get_args(MotionName)) == set(MOTIONS)
    assert set(get_args(StrengthLevel)) == set(STRENGTHS)
    assert set(get_args(StrengthTableName)) == set(STRENGTH_TABLES)


@pytest.mark.parametrize(
    ("flag", "value", "message"),
    [
        ("--workers", "0", "--workers 0 must be >= 1"),
        ("--nulls", "-1", "--nulls -1 must be >= 0"),
        ("--duration", "0", "--duration 0.0 must be > 0"),
        ("--strengths", "mid,huge", "argument --strengths: 'huge': choose from low, mid, high"),
        ("--motion", "run", "argument --motion: invalid choice: 'run'"),
        ("--part", "2/2", "argument --part: 2/2: need 0 <= i < n"),
        ("--part", "half", "argument --part: 'half': give I/N with whole numbers"),
        ("--seeds", "two", "argument --seeds: invalid int value: 'two'"),
    ],
)
def test_malformed_or_out_of_range_flags_exit_2(
    flag: str, value: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A malformed or out-of-range value is a usage error (exit code 2) naming the flag; nothing is written."""
    with pytest.raises(SystemExit) as stop:
        main(["--out", str(tmp_path / "sweep"), flag, value])
    assert stop.value.code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "sweep").exists()


def test_an_episode_with_stages_records_one_robot_per_stage_and_diagnoses_them_once(tmp_path: Path) -> None:
    """A gantry chirp and stepping of one robot with 1.5x armature: one row, one key per stage, the oracle energy."""
    ep = {"name": "staged", "effect": "joint.armature", "params": {"scale": [1.5]}, "strength": "mid", "seed": 5,
          "stages": [{"support": "gantry", "chirp": True}, {}]}  # fmt: skip
    row = sweep.run_episode(ep, str(tmp_path), 3.0, effects=("joint.armature", "actuator.delay", "terrain.cohesion"))
    assert row["verdict"] == "explained" and row["winner"] == "joint.armature", row
    ((value, lo, hi),) = row["fit"].values()
    assert abs(value - 1.5) < 0.15 and lo <= value <= hi
    key = json.loads((tmp_path / "keys" / "staged.json").read_text())
    assert [k["effect"] for k in key["stages"]] == ["joint.armature"] * 2
    en = row["energy"]
    assert en["oracle"] < en["nominal"] and en["fitted"] <= en["nominal"]
