# SPDX-License-Identifier: Apache-2.0
"""The soles' reach against the sand window, and the window that would hold it."""

from __future__ import annotations

from dataclasses import replace

import pytest

from gmloco.eval.mpm.window import SandWindowCfg


def test_a_run_reports_the_soles_reach_against_its_window(capsys: pytest.CaptureFixture[str]) -> None:
    """The largest reach over the episodes against the window's extent; a warning names the earliest exit."""
    from gmloco.eval.g1.window_report import report_window

    rows = [
        {
            "key": f"k{i}",
            "sole_behind_m": b,
            "sole_ahead_m": 0.15,
            "sole_side_m": 0.2,
            "window_exit_s": e,
            "window_exit_early": e is not None,
        }
        for i, (b, e) in enumerate([(0.3, None), (0.62, 0.8), (0.55, 0.5)])
    ]
    report_window(rows, SandWindowCfg(length=1.0, width=0.5, lead=0.1))
    err = capsys.readouterr().err
    assert "0.62 m behind the pelvis, 0.15 m ahead and 0.20 m sideways" in err
    assert "spans 0.40 m behind, 0.60 m ahead and 0.25 m sideways" in err
    assert "in 2 of 3 episodes" in err and "first at 0.50 s, k2" in err
    assert "turned" not in err  # rows without the cause (older runs) blame nothing on a turn
    rows[1]["window_exit_turn"] = True
    report_window(rows, SandWindowCfg(length=1.0, width=0.5, lead=0.1))
    assert "in 1 of them the robot had turned" in capsys.readouterr().err
    report_window(rows[:1], SandWindowCfg(length=1.0, width=0.5, lead=0.1))
    assert "warning" not in capsys.readouterr().err
    rows[1]["window_exit_turn"] = False  # reach only: rear 0.62 + 0.05 -> 0.70, front 0.60 and width 0.50 kept
    report_window(rows, SandWindowCfg(length=1.0, width=0.5, lead=0.1))
    assert "--window-length 1.3 --window-width 0.5 --window-lead -0.05" in capsys.readouterr().err


def test_a_covering_window_grows_only_where_the_soles_reached_past_it() -> None:
    """The per-terrain runs' poppy-seed reach against the tables' window, a turning walk, and a reach already held."""
    from gmloco.eval.g1.window_report import covering_window

    tables = SandWindowCfg(length=1.4, width=0.6, lead=0.2)  # 0.5 m behind, 0.9 ahead, 0.3 beside
    w = covering_window((0.73, 0.13, 0.31), tables, turned=False)
    assert (w.length, w.width, w.lead) == pytest.approx((1.7, 0.8, 0.05))  # rear 0.8, front 0.9 kept, 0.4 beside
    assert 0.5 * w.length - w.lead >= 0.73 and 0.5 * w.length + w.lead == pytest.approx(0.9)
    fixed = replace(tables, turn_with_robot=False)
    w = covering_window((0.45, 0.13, 0.2), fixed, turned=True)
    assert (w.length, w.width, w.lead) == pytest.approx((1.4, 1.4, 0.2))  # the square of the tables' window
    assert covering_window((0.45, 0.13, 0.2), tables, turned=True) == tables  # a turning window keeps its shape
    assert covering_window((0.45, 0.13, 0.2), tables, turned=False) == tables
