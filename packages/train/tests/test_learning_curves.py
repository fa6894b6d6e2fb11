# SPDX-License-Identifier: Apache-2.0
"""Learning-curve reading, chunk concatenation and the figure, on a two-chunk fixture."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from gmloco.train.learning_curves import (
    chunk_starts,
    fig_learning_curves,
    main,
    merge_curves,
    read_curve,
    robust_ylim,
)


@pytest.fixture
def run_dir(tmp_path: Path) -> Path:
    """A run folder: chunk A (iterations 0-3) as curve.csv, chunk B (resumed at 2, 2-5) as summary.json."""
    run = tmp_path / "gm_loco_teacher_x"
    run.mkdir()
    (run / "curve.csv").write_text(
        "iteration,mean_reward,action_std,loss_learning_rate\n0,1,1.0,1e-3\n1,2,0.9,5e-4\n2,3,0.8,\n3,4,0.7,2e-4\n"
    )
    curve_b = {
        "iteration": [2.0, 3.0, 4.0, 5.0],
        "mean_reward": [30.0, 40.0, 50.0, None],
        "loss_eta_r2": [0.5, 0.6, 0.7, 0.8],
        "yaw_rate_error": [0.4, 0.3, 0.2, 0.1],
    }
    (run / "chunk_b").mkdir()
    (run / "chunk_b" / "summary.json").write_text(json.dumps({"curve": curve_b}))
    manifest = {"chunks": [{"resumed_from_iteration": 0.0}, {"resumed_from_iteration": 2.0}]}
    (run / "manifest.json").write_text(json.dumps(manifest))
    return run


def test_merge_concatenates_by_iteration_later_chunk_wins(run_dir: Path) -> None:
    """Iterations 0-5 once each; 2 and 3 from chunk B; columns B lacks are NaN there, A's empty cell is NaN."""
    merged = merge_curves([read_curve(run_dir), read_curve(run_dir / "chunk_b" / "summary.json")])
    np.testing.assert_array_equal(merged["iteration"], [0, 1, 2, 3, 4, 5])
    np.testing.assert_array_equal(merged["mean_reward"][:5], [1, 2, 30, 40, 50])
    assert math.isnan(merged["mean_reward"][5])
    np.testing.assert_array_equal(np.isnan(merged["action_std"]), [False, False, True, True, True, True])
    np.testing.assert_array_equal(np.isnan(merged["loss_eta_r2"]), [True, True, False, False, False, False])


def test_chunk_starts_skip_the_first_chunk(run_dir: Path) -> None:
    """Only a chunk resumed after iteration 0 marks a start."""
    assert chunk_starts(run_dir / "manifest.json") == [2.0]
    assert chunk_starts(run_dir / "absent.json") == []


def test_figure_draws_the_logged_panels(run_dir: Path, tmp_path: Path) -> None:
    """Reward, lr, std, eta R^2 and yaw panels drawn; episode length (never logged) left out; a PNG written."""
    merged = merge_curves([read_curve(run_dir), read_curve(run_dir / "chunk_b" / "summary.json")])
    out = tmp_path / "curves.png"
    drawn = fig_learning_curves(merged, out, "fixture", starts=[2.0])
    assert drawn == ["mean episode reward", "learning rate", "action std [-]", "eta R^2 (batch)", "yaw tracking"]
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match="none of"):
        fig_learning_curves({"iteration": np.arange(3.0)}, out, "empty")


def test_cli_bad_source_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A folder without a curve is refused with exit code 2 and a message naming it."""
    assert main([str(tmp_path), "--out", str(tmp_path / "x.png")]) == 2
    assert "neither curve.csv nor summary.json" in capsys.readouterr().err


def test_robust_ylim_keeps_one_blown_up_point_off_scale() -> None:
    """A -1.8e11 reward among rewards of 0-100 is left off the axis and counted; a clean curve autoscales."""
    rewards = np.linspace(0.0, 100.0, 200)
    assert robust_ylim(rewards) is None
    blown = rewards.copy()
    blown[150] = -1.8e11
    low, high, outside = robust_ylim(blown)  # type: ignore[misc]
    assert outside == 1 and -400.0 < low < 0.0 and 100.0 < high < 500.0
