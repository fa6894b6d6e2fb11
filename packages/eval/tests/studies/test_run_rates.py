# SPDX-License-Identifier: Apache-2.0
"""A study folder's costs read back from its episodes and queue.json (issue 9)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gmloco.eval.studies.run_rates import TARGET_ROBOT_FRAMES_PER_S, folder_rates, main, run_rate, running_rates


def _episode(k: int, fps: float, alive: float, success: bool) -> dict:
    return {"key": f"dry_sand/straight/{k}", "success": success, "alive_s": alive, "frames_per_s": fps,
            "batch_size": 25, "particles": 1_880_000, "build_s": 30.0 + k}  # fmt: skip


def _study_folder(tmp_path: Path) -> Path:
    """Two shares of one row (GPU 0 and 1) and a lone task; the row took 9.5 min."""
    for name, fps, alive in (("row_share0of2", [4.0, 4.2, 4.4], [10.0, 10.0, 3.0]), ("row_share1of2", [4.4], [2.0]),
                             ("lone", [2.0, 2.0], [1.0, 1.5])):  # fmt: skip
        run = tmp_path / "runs" / name
        run.mkdir(parents=True)
        eps = [_episode(k, f, a, a >= 10.0) for k, (f, a) in enumerate(zip(fps, alive, strict=True))]
        (run / "episodes.jsonl").write_text("".join(json.dumps(e) + "\n" for e in eps))
    (tmp_path / "runs" / "empty").mkdir()  # a task that finished no episode
    (tmp_path / "logs").mkdir()
    queue = {"tasks": [{"name": "row_share0of2", "minutes": 9.5}, {"name": "row_share1of2", "minutes": 4.0},
                       {"name": "lone", "minutes": 2.0}],
             "rows": {"row": {"shares": 2, "gpus": ["0", "1"], "wall_minutes": 9.5, "returncodes": [0, 0]}}}  # fmt: skip
    (tmp_path / "logs" / "queue.json").write_text(json.dumps(queue))
    (tmp_path / "manifest.json").write_text(json.dumps({"device": "4 x H200", "code": "abc1234"}))
    return tmp_path


def test_run_rate_is_the_median_solver_rate_times_lanes() -> None:
    """Median of 4.0 / 4.2 / 4.4 frames/s with 25 lanes = 105 robot-frames/s; 200,000 robot-frames take 31.7 min."""
    r = run_rate([_episode(k, f, 10.0, True) for k, f in enumerate([4.4, 4.0, 4.2])])
    assert r["solver_frames_per_s_median"] == 4.2 and r["robot_frames_per_s_all_lanes"] == 105.0
    assert r["min_per_100_walking_episodes"] == round(200_000 / 105.0 / 60, 1)
    assert r["episodes"] == 3 and r["lanes"] == 25 and r["build_s"] == 30.0
    assert round(TARGET_ROBOT_FRAMES_PER_S, 1) == 333.3


def test_run_rate_refuses_empty_and_old_records() -> None:
    """No episodes, or records without the batch's rate fields: an error naming what is missing."""
    with pytest.raises(ValueError, match="no episodes"):
        run_rate([])
    with pytest.raises(ValueError, match="frames_per_s"):
        run_rate([{"key": "a", "success": True}])


def test_folder_rates_reads_runs_and_rows(tmp_path: Path) -> None:
    """Each run's rate and task minutes; the row pools its shares' episodes under queue.json's wall-clock."""
    out = folder_rates(_study_folder(tmp_path))
    assert set(out["runs"]) == {"row_share0of2", "row_share1of2", "lone"}  # the empty task has no rate
    assert out["runs"]["lone"]["task_minutes"] == 2.0 and out["device"] == "4 x H200"
    assert out["runs"]["lone"]["by_running_clock"].startswith("sim_s")  # records without elapsed_s
    row = out["rows"]["row"]
    assert row["wall_minutes"] == 9.5 and row["episodes"] == 4 and row["successes"] == 2
    assert row["longest_alive_s"] == 10.0 and row["build_s_max"] == 30.0


def test_folder_rates_without_queue_and_bad_folder(tmp_path: Path) -> None:
    """Without queue.json the runs still get rates (no rows); a folder without runs/ is refused."""
    root = _study_folder(tmp_path)
    (root / "logs" / "queue.json").unlink()
    out = folder_rates(root)
    assert out["rows"] == {} and out["runs"]["lone"]["task_minutes"] is None
    with pytest.raises(FileNotFoundError, match="no runs/ folder"):
        folder_rates(tmp_path / "runs" / "lone")


def test_main_writes_throughput_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The command line writes FOLDER/throughput.json and prints each row's wall-clock."""
    main([str(_study_folder(tmp_path))])
    assert json.loads((tmp_path / "throughput.json").read_text())["rows"]["row"]["shares"] == 2
    assert "row row: 9.5 min on GPUs 0 1" in capsys.readouterr().out


def test_rows_split_by_the_queue_shares_flag_are_found_too(tmp_path: Path) -> None:
    """``--shards`` names a cell's shares ``CELL__shareIofN``: their episodes pool under the row as task files' do."""
    root = _study_folder(tmp_path)
    for name in ("row_share0of2", "row_share1of2"):
        (root / "runs" / name).rename(root / "runs" / name.replace("row_", "dry_sand__straight__"))
    queue = json.loads((root / "logs" / "queue.json").read_text())
    queue["rows"] = {"dry_sand__straight": queue["rows"]["row"]}
    (root / "logs" / "queue.json").write_text(json.dumps(queue))
    assert folder_rates(root)["rows"]["dry_sand__straight"]["episodes"] == 4


def _rounded(out: dict[int, tuple[float, float]]) -> dict[int, tuple[float, float]]:
    return {n: (round(f, 6), round(t, 6)) for n, (f, t) in out.items()}


def _ends(ends: list[tuple[float, float]], build_s: float = 30.0, lanes: int | None = None) -> list[dict]:
    """A scene's episode records from (wall s, frame) at each end: the scene's clock and mean rate then."""
    n = lanes if lanes is not None else len(ends)
    return [{"key": f"k{i}", "sim_s": t, "frames_per_s": f / t, "batch_size": n, "build_s": build_s}
            for i, (t, f) in enumerate(ends)]  # fmt: skip


def test_running_rates_splits_a_batch_by_robots_walking() -> None:
    """Three lanes ending at 10 / 20 / 40 s (frames 40 / 60 / 80): 40 frames in 10 s with 3 walking, then 2, then 1."""
    out = running_rates(_ends([(20.0, 60.0), (10.0, 40.0), (40.0, 80.0)]))  # any line order
    assert _rounded(out) == {3: (40.0, 10.0), 2: (20.0, 10.0), 1: (20.0, 20.0)}
    assert list(out) == [3, 2, 1]


def test_running_rates_merges_short_stretches_by_frame_weight() -> None:
    """Ends 2 s apart merge with the next stretch: 4 frames with 2 walking + 36 with 1 is labelled 1 (44/40)."""
    out = running_rates(_ends([(10.0, 40.0), (12.0, 44.0), (40.0, 80.0)]), min_s=10.0)
    assert _rounded(out) == {3: (40.0, 10.0), 1: (40.0, 30.0)}


def test_running_rates_leaves_out_cut_batches() -> None:
    """A scene with fewer records than lanes (cut by a time box) is not rated; the next scene (another build) is."""
    cut = _ends([(10.0, 40.0), (20.0, 60.0)], build_s=30.0, lanes=3)
    whole = _ends([(5.0, 50.0), (15.0, 70.0)], build_s=31.0)
    assert _rounded(running_rates(cut + whole, min_s=1.0)) == {2: (50.0, 5.0), 1: (20.0, 10.0)}
    assert running_rates([{"key": "a", "batch_size": 1, "build_s": 1.0, "frames_per_s": 2.0}]) == {}


def test_running_rates_prefers_the_elapsed_clock() -> None:
    """Records with ``elapsed_s`` / ``end_frame`` (the transition-course runs on) are timed by them, not by the in-step ``sim_s``."""
    eps = _ends([(10.0, 40.0), (20.0, 60.0)])
    for e, (elapsed, frame) in zip(eps, [(12.0, 40), (24.0, 60)], strict=True):
        e |= {"elapsed_s": elapsed, "end_frame": frame}
    assert _rounded(running_rates(eps)) == {2: (40.0, 12.0), 1: (20.0, 12.0)}


def test_run_rate_reads_the_wall_clock_where_records_have_it() -> None:
    """The rate from end_frame / elapsed_s where recorded, else from the stepping clock's frames_per_s."""
    # a batch of 2000 frames: the stepping clock says 2.0 frames/s, the wall clock (waits included) 1.8
    eps = [_episode(k, 2.0, 10.0, True) | {"end_frame": 2000, "elapsed_s": 2000 / 1.8} for k in range(3)]
    r = run_rate(eps)
    assert r["rate_clock"] == "elapsed_s"
    assert r["solver_frames_per_s_median"] == pytest.approx(1.8, abs=1e-3)
    assert r["robot_frames_per_s_all_lanes"] == pytest.approx(45.0, abs=0.1)
    # a run resumed from an older record without the wall clock: the rate comes from the records that have it
    eps[0] = {k: v for k, v in eps[0].items() if k not in ("end_frame", "elapsed_s")} | {"frames_per_s": 5.0}
    assert run_rate(eps)["solver_frames_per_s_median"] == pytest.approx(1.8, abs=1e-3)
    # no record has it (runs before the transition-course runs): the stepping clock
    old = [{k: v for k, v in e.items() if k not in ("end_frame", "elapsed_s")} for e in eps]
    r = run_rate(old)
    assert r["rate_clock"] == "sim_s" and r["solver_frames_per_s_median"] == pytest.approx(2.0)


def test_run_rate_of_a_resumed_run_is_its_widest_batches() -> None:
    """A run resumed across machines: 3 episodes of a 3-lane refit batch, then 22 of a 22-lane one.

    The rate is the 22-lane batch's (2.0 frames/s x 22 lanes = 44 robot-frames/s), not its median frame rate
    times the first record's 3 lanes; the narrow batch is listed apart.
    """
    narrow = [_episode(k, 6.0, 10.0, True) | {"batch_size": 3} for k in range(3)]
    wide = [_episode(3, 2.0, 10.0, True) | {"batch_size": 22, "key": f"dry_sand/straight/{k}"} for k in range(3, 25)]
    r = run_rate(narrow + wide)
    assert r["lanes"] == 22 and r["episodes"] == 25 and r["other_lanes"] == {"3": 3}
    assert r["solver_frames_per_s_median"] == pytest.approx(2.0)
    assert r["robot_frames_per_s_all_lanes"] == pytest.approx(44.0)
    assert run_rate(wide)["other_lanes"] == {}
