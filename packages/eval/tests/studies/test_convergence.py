# SPDX-License-Identifier: Apache-2.0
"""The MPM setting check: same walks are accepted, a changed walk is rejected, a handful of episodes decides nothing."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gmloco.eval.metrics.episodes import load_episodes
from gmloco.eval.studies.convergence import ConvergenceCfg, compare_runs, main


def _rows(alive: np.ndarray, sink: float, success_frac: float, speed: float = 1.0, vel: float = 0.2) -> list[dict]:
    n = len(alive)
    wins = round(success_frac * n)
    return [{"terrain": "dry_sand", "scenario": "straight", "speed": speed, "alive_s": float(a),
             "success": k < wins, "mean_sinkage": sink, "vel_error": vel + 0.002 * (k % 5),
             "yaw_error": 0.5 + 0.01 * (k % 3)} for k, a in enumerate(alive)]  # fmt: skip


def test_the_same_walk_twice_is_accepted() -> None:
    """Two draws from one distribution of fall times, equal sinkage and success: accepted."""
    rng = np.random.default_rng(0)
    v = compare_runs(_rows(rng.uniform(4, 10, 20), 0.08, 0.3), _rows(rng.uniform(4, 10, 20), 0.082, 0.3))
    assert v.decision == "accepted" and not v.reasons
    assert v.episodes == (20, 20)


def test_earlier_falls_are_rejected_and_named() -> None:
    """Falls 3 s earlier at the candidate setting: rejected, the reason names the time alive."""
    rng = np.random.default_rng(1)
    v = compare_runs(_rows(rng.uniform(5, 9, 16), 0.08, 0.0), _rows(rng.uniform(2, 6, 16), 0.08, 0.0))
    assert v.decision == "rejected"
    assert any("time alive" in r for r in v.reasons)


def test_deeper_sinkage_alone_is_rejected() -> None:
    """Same falls but 30 % more sinkage: rejected on sinkage only."""
    alive = np.linspace(3, 10, 12)
    v = compare_runs(_rows(alive, 0.08, 0.25), _rows(alive, 0.104, 0.25))
    assert v.decision == "rejected" and len(v.reasons) == 1 and "sinkage" in v.reasons[0]
    assert v.sinkage_rel_diff == pytest.approx(0.3)


def test_worse_velocity_tracking_alone_is_rejected() -> None:
    """Same falls and sinkage, velocity error 0.30 instead of 0.20 m/s (a table metric): rejected on it alone."""
    alive = np.full(8, 5.0)
    v = compare_runs(_rows(alive, 0.045, 1.0), _rows(alive, 0.045, 1.0, vel=0.3))
    assert v.decision == "rejected" and len(v.reasons) == 1 and "velocity tracking" in v.reasons[0]
    assert v.vel_error_median[0] > v.vel_error_median[1]
    assert v.yaw_error_p == pytest.approx(1.0)


def test_episodes_without_a_tracking_error_are_left_out() -> None:
    """``vel_error`` None (no measured motion) drops that episode from the velocity test only."""
    alive = np.linspace(3, 10, 10)
    cand = _rows(alive, 0.08, 0.2)
    cand[0]["vel_error"] = None
    v = compare_runs(_rows(alive, 0.08, 0.2), cand)
    assert v.decision == "accepted" and np.isfinite(v.vel_error_median[0])


def test_a_handful_of_episodes_is_undecided() -> None:
    """Four episodes against sixteen: undecided, whatever the tests say."""
    alive = np.linspace(3, 10, 16)
    v = compare_runs(_rows(alive, 0.08, 0.25), _rows(alive[:4], 0.08, 0.25), ConvergenceCfg(min_episodes=8))
    assert v.decision == "undecided" and "too few episodes" in v.reasons[0]


def test_runs_of_different_commands_are_refused() -> None:
    """1.0 m/s against 1.5 m/s is not a setting comparison: a ValueError that says so."""
    alive = np.linspace(3, 10, 10)
    with pytest.raises(ValueError, match="different"):
        compare_runs(_rows(alive, 0.08, 0.2), _rows(alive, 0.08, 0.2, speed=1.5))


def test_command_line_pools_runs_and_writes_the_verdict(tmp_path: Path) -> None:
    """Two reference folders are pooled; the verdict JSON holds the decision and the episode counts."""
    alive = np.linspace(3, 10, 10)
    for name, rows in (("a", _rows(alive, 0.08, 0.2)), ("b", _rows(alive, 0.08, 0.2)), ("c", _rows(alive, 0.08, 0.2))):
        (tmp_path / name).mkdir()
        (tmp_path / name / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    out = tmp_path / "verdict.json"
    v = main(["--reference", str(tmp_path / "a"), str(tmp_path / "b"), "--candidate", str(tmp_path / "c"),
              "--out", str(out)])  # fmt: skip
    assert v.episodes == (10, 20)
    assert json.loads(out.read_text())["decision"] == "accepted"


def test_a_folder_without_episodes_is_a_clear_error(tmp_path: Path) -> None:
    """No episodes.jsonl: FileNotFoundError naming what to pass."""
    with pytest.raises(FileNotFoundError, match=r"episodes\.jsonl"):
        load_episodes(tmp_path)


def test_a_file_that_is_not_an_episodes_file_is_a_clear_error(tmp_path: Path) -> None:
    """A run's log passed by mistake: ValueError naming what to pass, not a complaint about its first line."""
    log = tmp_path / "run.log"
    log.write_text("cell 1/1 ...\n")
    with pytest.raises(ValueError, match=r"not an episodes file"):
        load_episodes(log)


def test_a_run_cut_short_by_its_time_box_is_undecided(tmp_path: Path) -> None:
    """Equal walks, but the reference's summary.json says incomplete: undecided, and the reason names the folder."""
    alive = np.linspace(3, 10, 10)
    for name, complete in (("ref", False), ("cand", True)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in _rows(alive, 0.08, 0.2)))
        (tmp_path / name / "summary.json").write_text(json.dumps({"complete": complete, "cfg": {"num_episodes": 16}}))
    v = main(["--reference", str(tmp_path / "ref"), "--candidate", str(tmp_path / "cand")])
    assert v.decision == "undecided"
    assert len(v.reasons) == 1 and "ref is incomplete (10 of 16 episodes)" in v.reasons[0]
    complete = compare_runs(_rows(alive, 0.08, 0.2), _rows(alive, 0.08, 0.2))
    assert complete.decision == "accepted"  # the same episodes without the flag
    # a share of a two-terrain run (--shard 1/4 of 32 per cell) asks for 2 x 8 episodes
    cfg = {"num_episodes": 32, "shard": 1, "shards": 4, "terrains": ["basalt", "dry_sand"], "scenarios": ["straight"]}
    (tmp_path / "ref" / "summary.json").write_text(json.dumps({"complete": False, "cfg": cfg}))
    v = main(["--reference", str(tmp_path / "ref"), "--candidate", str(tmp_path / "cand")])
    assert "ref is incomplete (10 of 16 episodes)" in v.reasons[0]


def _with_floor(rows: list[dict], hits: int) -> list[dict]:
    """The first ``hits`` episodes had a sole reach the bed's rigid floor."""
    return [r | {"floor_reached": k < hits} for k, r in enumerate(rows)]


def test_soles_reaching_the_floor_more_often_are_rejected() -> None:
    """Same walks, but a sole reached the floor in 14 of 16 episodes against 2 of 16: rejected on the floor."""
    alive = np.full(16, 10.0)
    v = compare_runs(_with_floor(_rows(alive, 0.08, 0.5), 2), _with_floor(_rows(alive, 0.08, 0.5), 14))
    assert v.decision == "rejected" and v.floor_reached == (14, 2)
    assert [r for r in v.reasons if "floor" in r] == [r for r in v.reasons]  # the floor is the only reason
    same = compare_runs(_with_floor(_rows(alive, 0.08, 0.5), 3), _with_floor(_rows(alive, 0.08, 0.5), 4))
    assert same.decision == "accepted" and same.floor_p > 0.05


def test_runs_without_floor_records_skip_the_floor_test() -> None:
    """Older runs (no ``floor_reached``): the test is skipped, p = 1, nothing counted."""
    alive = np.full(10, 10.0)
    v = compare_runs(_rows(alive, 0.08, 0.5), _with_floor(_rows(alive, 0.08, 0.5), 10))
    assert v.floor_p == 1.0 and v.decision == "accepted"


def test_sinkage_interval_brackets_the_difference_and_narrows_with_episodes() -> None:
    """Candidate 10 % deeper on average: the 95 % interval holds +10 % and is narrower with 4x the episodes."""
    rng = np.random.default_rng(3)

    def run(n: int, mean: float) -> list[dict]:
        rows = _rows(np.full(n, 10.0), 0.0, 0.5)
        return [r | {"mean_sinkage": float(s)} for r, s in zip(rows, rng.normal(mean, 0.01, n), strict=True)]

    small = compare_runs(run(16, 0.07), run(16, 0.077))
    large = compare_runs(run(64, 0.07), run(64, 0.077))
    for v in (small, large):
        lo, hi = v.sinkage_rel_ci95
        assert lo < 0.10 < hi
    assert np.diff(large.sinkage_rel_ci95)[0] < np.diff(small.sinkage_rel_ci95)[0]


def test_sinkage_interval_skips_episodes_without_a_sinkage() -> None:
    """A NaN sinkage (no sole near the sand) is left out of the interval, as out of the means."""
    alive = np.full(12, 10.0)
    cand = _rows(alive, 0.08, 0.5)
    cand[0]["mean_sinkage"] = float("nan")
    lo, hi = compare_runs(_rows(alive, 0.08, 0.5), cand).sinkage_rel_ci95
    assert np.isfinite(lo) and np.isfinite(hi) and lo <= 0.0 <= hi


def test_a_drifting_heading_alone_is_rejected_and_older_runs_skip_it() -> None:
    """Same walks but 12 instead of 2 degrees of heading error (the paper's yaw metric): rejected on it alone.

    Runs older than the metric (no ``heading_error_deg``) leave the test out: p = 1, medians NaN.
    """
    alive = np.full(8, 5.0)
    ref, cand = _rows(alive, 0.045, 1.0), _rows(alive, 0.045, 1.0)
    for k, (r, c) in enumerate(zip(ref, cand, strict=True)):
        r["heading_error_deg"], c["heading_error_deg"] = 2.0 + 0.1 * k, 12.0 + 0.1 * k
    v = compare_runs(ref, cand)
    assert v.decision == "rejected" and len(v.reasons) == 1 and "heading error" in v.reasons[0]
    assert v.heading_error_median == pytest.approx((12.35, 2.35))
    old = compare_runs(_rows(alive, 0.045, 1.0), _rows(alive, 0.045, 1.0))
    assert old.decision == "accepted" and old.heading_error_p == 1.0 and np.isnan(old.heading_error_median).all()
