# SPDX-License-Identifier: Apache-2.0
"""Combined paper tables: policies side by side, like settings only, partial rows named, the success interval."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from gmloco.eval.metrics.episodes import wilson_interval
from gmloco.eval.report.paper_tables import combine, main

SETTING = {"solver": {"voxel_size": 0.03, "max_iterations": 500, "frame_dt": 0.005}, "window": {"length": 1.4},
           "bed_depth": 0.3, "episode_s": 10.0, "failure": {"max_tilt": 0.785}, "course_slack": 0.2,
           "circle_radius": 2.0}  # fmt: skip


def _run(root: Path, name: str, wins: int, n: int, speeds: tuple[float, ...] = (1.0,), **setting: object) -> Path:
    """A g1_eval-shaped run folder: ``wins`` successes of ``n`` dry-sand straight episodes."""
    d = root / name
    d.mkdir()
    cfg = json.loads(json.dumps(SETTING)) | setting | {"seed": len(name), "max_minutes": 9.0}
    (d / "summary.json").write_text(json.dumps({"cfg": cfg, "policy": f"artifacts/{name}/policy.onnx"}))
    rows = [{"terrain": "dry_sand", "scenario": "straight", "speed": speeds[k % len(speeds)], "success": k < wins,
             "alive_s": 10.0, "vel_error": 0.2, "yaw_error": 0.1, "path_error": 0.3, "mean_sinkage": 0.05,
             "swing_apex": 0.02, "swing_lift": 0.08} for k in range(n)]  # fmt: skip
    (d / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    return d


def test_wilson_interval_known_values() -> None:
    """50 of 100: 40.4-59.6 %; 8 of 8: at least 67.6 %; 0 of 10: at most 27.8 % (textbook Wilson values)."""
    assert wilson_interval(50, 100) == pytest.approx((0.4038, 0.5962), abs=1e-4)
    assert wilson_interval(8, 8) == pytest.approx((0.6756, 1.0), abs=1e-4)
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-4)
    assert wilson_interval(0, 69)[0] == 0.0 and wilson_interval(69, 69)[1] == 1.0  # exact ends, no rounding noise


def test_two_policies_side_by_side_with_partial_rows_named(tmp_path: Path) -> None:
    """100 episodes of one policy and 8 of another: two rows, the short one marked incomplete."""
    a, b = _run(tmp_path, "a", 50, 100, speeds=(1.0, 2.0)), _run(tmp_path, "b", 8, 8)
    summary = combine([("td", a), ("clr50", b)], tmp_path / "out")
    rows = list(csv.DictReader((tmp_path / "out" / "table_terrains.csv").open()))
    assert [r["policy"] for r in rows] == ["td", "clr50"]
    assert float(rows[0]["success_rate_pct"]) == pytest.approx(50.0)
    assert float(rows[0]["success_lo95_pct"]) == pytest.approx(40.38, abs=0.01)
    assert [r["complete"] for r in rows] == ["yes", "no"]
    assert summary["partial_rows"] == ["clr50/dry_sand/straight: 8 of 100 episodes"]
    assert summary["runs"]["clr50"]["policy"] == "artifacts/b/policy.onnx"  # provenance of every row
    speeds = list(csv.DictReader((tmp_path / "out" / "table_speeds.csv").open()))
    # the union of speeds is the header (td: the first 50 episodes, alternating speeds, won: 50 % each); clr50 ran
    # no 2 m/s episode: NaN there
    assert (speeds[0]["v=1 m/s"], speeds[0]["v=2 m/s"], speeds[1]["v=2 m/s"]) == ("50.0", "50.0", "nan")


def test_runs_at_different_settings_are_refused_by_name(tmp_path: Path) -> None:
    """500 vs 250 iterations: a ValueError naming the field; with allow_mixed the difference is recorded."""
    a = _run(tmp_path, "a", 5, 10)
    b = _run(tmp_path, "b", 5, 10, solver={"voxel_size": 0.03, "max_iterations": 250, "frame_dt": 0.005})
    with pytest.raises(ValueError, match=r"solver\.max_iterations \(500 vs 250\)"):
        combine([("x", a), ("y", b)], tmp_path / "out")
    summary = combine([("x", a), ("y", b)], tmp_path / "out", allow_mixed=True)
    assert summary["mixed_settings"]["y"] == ["solver.max_iterations (500 vs 250)"]
    for md in (tmp_path / "out").glob("table_*.md"):
        assert md.read_text().endswith("- `y`: solver.max_iterations (500 vs 250)\n"), md.name


def test_a_rows_shares_at_one_other_setting_are_named_once(tmp_path: Path) -> None:
    """Three shares of one label all at a wider window: one note line under the label.

    A label with one differing folder among two names that folder.
    """

    def share(name: str, policy: str, **setting: object) -> Path:
        d = _run(tmp_path, name, 1, 2, **setting)
        sm = json.loads((d / "summary.json").read_text()) | {"policy": policy}
        (d / "summary.json").write_text(json.dumps(sm))
        return d

    wide = {"window": {"length": 1.4, "width": 1.3}}
    runs = [("x", share("a", "x"))] + [("y", share(f"y{i}", "y", **wide)) for i in range(3)]
    odd = share("z1", "z", **wide)
    runs += [("z", share("z0", "z")), ("z", odd)]
    mixed = combine(runs, tmp_path / "out", 2, allow_mixed=True)["mixed_settings"]
    assert mixed == {"y": ["window.width (None vs 1.3)"], f"z ({odd})": ["window.width (None vs 1.3)"]}


def test_seeds_and_time_boxes_may_differ(tmp_path: Path) -> None:
    """Fields outside the setting (seed, max_minutes) do not split a table."""
    summary = combine([("x", _run(tmp_path, "a", 1, 2)), ("y", _run(tmp_path, "bb", 2, 2))], tmp_path / "o", 2)
    assert summary["mixed_settings"] == {} and summary["partial_rows"] == []


def test_command_line_errors_say_what_to_pass(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A --run without LABEL=, a folder without summary.json and one label on two policies are usage errors."""
    run, other = _run(tmp_path, "a", 1, 2), _run(tmp_path, "b", 1, 2)
    for argv, msg in ((["--run", str(run)], "LABEL=RUN_DIR"), (["--run", f"x={tmp_path}"], "no summary.json"),
                      (["--run", f"x={run}", "--run", f"x={other}"], "different policies")):  # fmt: skip
        with pytest.raises(SystemExit):
            main([*argv, "--out", str(tmp_path / "out")])
        assert msg in capsys.readouterr().err


def test_summary_file_holds_the_rows_as_records(tmp_path: Path) -> None:
    """--summary writes tables.json's content (rows as records, the tables' folder) to the given file."""
    run = _run(tmp_path, "a", 3, 4, speeds=(1.0, 2.0))
    out, summary_path = tmp_path / "tables", tmp_path / "mpm" / "summary.json"
    main(["--run", f"td={run}", "--out", str(out), "--episodes", "4", "--summary", str(summary_path)])
    summary = json.loads(summary_path.read_text())
    assert summary["tables"] == str(out)
    assert summary["rows"][0]["policy"] == "td" and summary["rows"][0]["complete"] == "yes"
    assert summary["rows"][0]["success_rate_pct"] == pytest.approx(75.0)
    assert summary["speed_rows"][0]["v=1 m/s"] == pytest.approx(100.0)
    assert summary["speed_rows"][0]["v=2 m/s"] == pytest.approx(50.0)
    cell = summary["paper_metrics"]["td"]["dry_sand"]["straight"]  # the paper's keys per (policy, terrain, scenario)
    assert set(cell) == {"success_pct", "vel_error_mps", "heading_error_deg", "path_error_m", "episodes"}
    assert cell["success_pct"] == pytest.approx(75.0) and cell["episodes"] == summary["rows"][0]["episodes"]
    assert json.loads((out / "tables.json").read_text())["rows"] == summary["rows"]


def test_a_figure_per_cell_puts_the_policies_side_by_side(tmp_path: Path) -> None:
    """Two policies on one dry-sand cell at two speeds: one figure, named after the cell, listed in tables.json."""
    a = _run(tmp_path, "a", 3, 8, speeds=(1.0, 2.0))
    b = _run(tmp_path, "b", 0, 8, speeds=(1.0, 2.0))
    summary = combine([("x", a), ("y", b)], tmp_path / "out")
    tables = ["fig_table_terrains.png", "fig_table_speeds.png", "fig_table_ablation.png", "fig_table_per_terrain.png"]
    assert summary["figures"] == ["fig_speeds_dry_sand_straight.png", *tables, "fig_per_terrain.png"]
    assert (tmp_path / "out" / "fig_speeds_dry_sand_straight.png").stat().st_size > 10_000
    assert (tmp_path / "out" / "fig_per_terrain.png").stat().st_size > 10_000


def test_rows_whose_soles_left_the_window_are_named(tmp_path: Path) -> None:
    """3 of 10 early window exits: the row is listed in tables.json and under the markdown table; 0 of 10 is not."""
    a, b = _run(tmp_path, "a", 5, 10), _run(tmp_path, "b", 5, 10)
    for d, exits in ((a, 3), (b, 0)):
        rows = [json.loads(line) for line in (d / "episodes.jsonl").read_text().splitlines()]
        for k, r in enumerate(rows):
            r["window_exit_early"] = k < exits
        (d / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    summary = combine([("rigid", a), ("td", b)], tmp_path / "out")
    assert summary["window_exit_rows"] == {"rigid/dry_sand/straight": 30.0}
    md = (tmp_path / "out" / "table_terrains.md").read_text()
    assert "`rigid/dry_sand/straight`: 30 % of episodes" in md and "`td/dry_sand" not in md
    assert summary["window_exit_turn_rows"] == {}  # runs that did not record why: no cause claimed
    assert "by the robot's turn" not in md


def test_exits_by_a_turn_are_named_with_their_share(tmp_path: Path) -> None:
    """4 of 10 early exits, 3 of them by the robot's turn: the note gives 30 % by turn and asks for a turning window."""
    a = _run(tmp_path, "a", 5, 10)
    rows = [json.loads(line) for line in (a / "episodes.jsonl").read_text().splitlines()]
    for k, r in enumerate(rows):
        r["window_exit_early"], r["window_exit_turn"] = k < 4, k < 3
    (a / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    summary = combine([("td", a)], tmp_path / "out")
    assert summary["window_exit_rows"] == {"td/dry_sand/straight": 40.0}
    assert summary["window_exit_turn_rows"] == {"td/dry_sand/straight": 30.0}
    md = (tmp_path / "out" / "table_terrains.md").read_text()
    assert "40 % of episodes (30 % by the robot's turn: give it a turning window)" in md


def test_runs_older_than_the_window_check_are_not_named(tmp_path: Path) -> None:
    """Episodes without ``window_exit_early`` (NaN column) add no note."""
    summary = combine([("td", _run(tmp_path, "a", 5, 10))], tmp_path / "out")
    assert summary["window_exit_rows"] == {}
    assert "left the sand window" not in (tmp_path / "out" / "table_terrains.md").read_text()


def test_the_paper_layouts_are_written(tmp_path: Path) -> None:
    """``table_ablation`` and ``table_per_terrain`` (markdown + CSV) come with the combined tables."""
    combine([("td", _run(tmp_path, "a", 5, 10)), ("rigid", _run(tmp_path, "b", 0, 10))], tmp_path / "out")
    ablation = list(csv.DictReader((tmp_path / "out" / "table_ablation.csv").open()))
    assert [(r["policy"], r["straight_success_pct"]) for r in ablation] == [("td", "50.0"), ("rigid", "0.0")]
    per_terrain = list(csv.DictReader((tmp_path / "out" / "table_per_terrain.csv").open()))
    assert per_terrain[0]["terrain"] == "dry_sand" and per_terrain[0]["rigid: success %"] == "0.0"
    assert (tmp_path / "out" / "table_per_terrain.md").is_file()


def test_folders_with_one_label_are_pooled(tmp_path: Path) -> None:
    """One policy scored in two folders (two GPUs): one row of 20 episodes, both folders in the provenance."""
    a, b = _run(tmp_path, "a", 5, 10), _run(tmp_path, "b", 3, 10)
    doc = json.loads((b / "summary.json").read_text())
    (b / "summary.json").write_text(json.dumps(doc | {"policy": "artifacts/a/policy.onnx"}))
    summary = combine([("td", a), ("td", b)], tmp_path / "out", episodes=20)
    assert [(r["policy"], r["episodes"], r["success_rate_pct"]) for r in summary["rows"]] == [("td", 20, 40.0)]
    assert summary["runs"]["td"]["dirs"] == [str(a), str(b)] and summary["partial_rows"] == []


def test_a_runs_file_lists_labels_and_globs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """LABEL=DIR lines with comments; a glob pools a row's shares; a line matching nothing is named."""
    from gmloco.eval.report.paper_tables import runs_file

    shares = [_run(tmp_path, f"row_share{i}of2", i + 1, 2) for i in range(2)]
    for d in shares:  # both shares scored one policy
        doc = json.loads((d / "summary.json").read_text())
        (d / "summary.json").write_text(json.dumps(doc | {"policy": "artifacts/td/policy.onnx"}))
    other = _run(tmp_path, "rigid", 0, 4)
    f = tmp_path / "runs.txt"
    f.write_text(f"# the td row in two shares\ntd={tmp_path}/row_share*of2\n\nrigid={other}  # baseline\n")
    assert runs_file(f) == [("td", shares[0]), ("td", shares[1]), ("rigid", other)]
    summary = main(["--runs-file", str(f), "--out", str(tmp_path / "out"), "--episodes", "4"])
    assert [(r["policy"], r["episodes"]) for r in summary["rows"]] == [("td", 4), ("rigid", 4)]
    f.write_text(f"td={tmp_path}/nothing_here*\n")
    with pytest.raises(SystemExit):
        main(["--runs-file", str(f), "--out", str(tmp_path / "out")])
    assert "runs.txt:1" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--out", str(tmp_path / "out")])
    assert "--runs-file" in capsys.readouterr().err


def test_the_transition_course_gets_its_table_and_figure(tmp_path: Path) -> None:
    """Layered episodes: one table row per medium reached (pooled over speeds) and a figure per policy label."""
    d = _run(tmp_path, "td", 1, 4, speeds=(1.0, 2.0))
    layer = {"steps": 10, "swings": 2, "swing_apex": 0.02, "swing_lift": 0.08}
    rows = [json.loads(line) for line in (d / "episodes.jsonl").read_text().splitlines()]
    for k, r in enumerate(rows):  # every walk crosses basalt; the two at 1 m/s (k = 0, 2) reach the dry sand
        r |= {"terrain": "transition", "layers": [layer | {"medium": "basalt", "eta_mean": 0.3 + 0.1 * (k % 2)},
              layer | {"medium": "dry_sand", "eta_mean": 0.2, "steps": 10 * (k % 2 == 0)}]}  # fmt: skip
    (d / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    summary = combine([("td", d)], tmp_path / "out", episodes=4)
    table = list(csv.DictReader((tmp_path / "out" / "table_transition.csv").open()))
    assert [(r["medium"], r["episodes_reached"]) for r in table] == [("basalt", "4"), ("dry_sand", "2")]
    assert float(table[0]["eta_decoded"]) == pytest.approx(0.35) and float(table[0]["swing_lift_cm"]) == 8.0
    assert "fig_transition_td.png" in summary["figures"] and (tmp_path / "out" / "fig_transition_td.png").stat().st_size
