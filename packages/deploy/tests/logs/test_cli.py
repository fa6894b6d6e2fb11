# SPDX-License-Identifier: Apache-2.0
"""``gmloco-logs`` end to end on the committed sample recordings."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import pytest

from gmloco.deploy.logs.analysis import analyze
from gmloco.deploy.logs.cli import main


def test_cli_on_committed_samples(tmp_path: Path, samples_dir: Path) -> None:
    """The CLI writes summary.md/.csv/.json and the figures for every sample, with sane numbers."""
    pytest.importorskip("matplotlib")
    files = sorted(samples_dir.glob("*.mcap"))
    assert len(files) >= 2, "sample recordings missing; run packages/deploy/scripts/make_sample_logs.py"
    out = tmp_path / "out"
    assert main([str(samples_dir), "--out", str(out), "--no-progress"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    runs = {r["file"]: r for r in summary["runs"]}
    assert set(runs) == {f.name for f in files}
    stair = runs["g1_scripted_rigid_staircase.mcap"]
    assert stair["controller"] == "scripted_stepping" and stair["policy"] == "none"
    assert stair["velocity_source"] == "odometry"
    assert stair["segmentation_agreement"] > 0.8  # FK-based stance vs MuJoCo contact truth
    assert stair["leg_odometry_rmse_mps"] < 0.2  # leg odometry vs ground-truth odometry
    assert 0.02 < stair["clearance_mean_m"] < 0.15 and stair["n_swings"] > 10
    assert runs["g1_scripted_rigid_no_odometry.mcap"]["velocity_source"] == "leg_odometry"
    cmds: dict[str, set[float]] = {}
    for row in summary["tracking"]:
        cmds.setdefault(row["controller"], set()).add(round(row["cmd"], 3))
    assert sorted(cmds.pop("scripted_stepping")) == [0.0, 0.2, 0.3, 0.4]  # make_sample_logs.py's schedule
    assert all(c == {1.0} for c in cmds.values()), cmds  # the policy samples are commanded 1.0 m/s (README)
    with open(out / "summary.csv") as f:
        assert len(list(csv.DictReader(f))) == len(files)
    assert "Velocity tracking per commanded speed" in (out / "summary.md").read_text()
    for name in ("fig_velocity_tracking", "fig_ankle_pitch_torque", "fig_swing_clearance"):
        assert (out / "figures" / f"{name}.png").stat().st_size > 10_000


def test_analyze_reports_damaged_and_unreadable_files(tmp_path: Path, samples_dir: Path) -> None:
    """A truncated sample is analyzed up to the damage; a non-MCAP file is listed as a failure."""
    src = samples_dir / "g1_scripted_rigid_no_odometry.mcap"
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(src.read_bytes()[: src.stat().st_size // 2])
    junk = tmp_path / "junk.mcap"
    junk.write_text("not a log")
    with pytest.warns(UserWarning):
        result = analyze([cut, junk], tmp_path / "out", figures=False, progress=False)
    assert [r["file"] for r in result["runs"]] == ["cut.mcap"] and result["runs"][0]["damaged"]
    assert result["failures"][0]["file"].endswith("junk.mcap")
    assert any("damaged at byte" in w for w in result["warnings"][str(cut)])


def test_analyze_never_overwrites_inputs(tmp_path: Path, samples_dir: Path) -> None:
    """An input named like an output in the output directory is refused before anything is written."""
    victim = tmp_path / "summary.json"
    shutil.copy(samples_dir / "g1_scripted_rigid_no_odometry.mcap", victim)
    before = victim.read_bytes()
    with pytest.raises(ValueError, match="would overwrite an input"):
        analyze([victim], tmp_path, figures=False, progress=False)
    assert victim.read_bytes() == before


@pytest.mark.parametrize("content", [[], ["notes.txt"]])
def test_cli_refuses_a_folder_without_recordings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: list[str]
) -> None:
    """An empty folder (or one without ``*.mcap``) exits 2 with one paragraph and writes no summary."""
    folder = tmp_path / "logs"
    folder.mkdir()
    for name in content:
        (folder / name).write_text("x")
    out = tmp_path / "out"
    assert main([str(folder), "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "holds no *.mcap recording" in err and str(folder) in err and err.count("\n") == 1
    assert not out.exists()


def test_cli_refuses_a_missing_path(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A path that does not exist exits 2 before anything is analyzed."""
    assert main([str(tmp_path / "nope.mcap"), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    assert "does not exist" in capsys.readouterr().err
