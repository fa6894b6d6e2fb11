# SPDX-License-Identifier: Apache-2.0
"""Recorded walks against commanded paths: a hand-made circle read back in its start frame; the figures get drawn."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("mcap")


def _circle_episode(v: float, wz: float, yaw0: float, start: tuple[float, float], n: int, dt: float) -> dict:
    """A walk exactly on the (v, wz) circle from ``start`` heading ``yaw0``, as ``write_episode_mcap`` takes it."""
    from gmloco.deploy.logs import G1_JOINT_NAMES
    from gmloco.eval.metrics.locomotion import circular_path

    xy, yaw = circular_path(v, wz, (n - 1) * dt, dt, start_xy=start, start_yaw=yaw0)
    q = np.zeros((n, 7))
    q[:, :2], q[:, 2] = xy, 0.7
    q[:, 5], q[:, 6] = np.sin(0.5 * yaw), np.cos(0.5 * yaw)  # x y z w, a turn about z
    qd = np.zeros((n, 6))
    qd[:, 0], qd[:, 1], qd[:, 5] = v * np.cos(yaw), v * np.sin(yaw), wz
    zeros = np.zeros((n, 29))
    return {"dt": dt, "base_q": q, "base_qd": qd, "joint_q": zeros, "joint_qd": zeros, "target": zeros,
            "action": zeros, "foot_force": np.zeros((n, 2, 3)), "foot_sinkage": np.zeros((n, 2)),
            "command": (v, 0.0, wz), "joint_names": list(G1_JOINT_NAMES), "kp": np.ones(29), "kd": np.ones(29)}  # fmt: skip


def _record(run: Path, name: str, ep: dict, end_reason: str = "completed") -> Path:
    from gmloco.eval.g1.record import write_episode_mcap

    (run / "recordings").mkdir(parents=True, exist_ok=True)
    meta = {"policy": "p", "material": "dry_sand", "end_reason": end_reason}
    return write_episode_mcap(run / "recordings" / f"{name}.mcap", ep, meta)


def test_a_circle_reads_back_in_its_start_frame(tmp_path: Path) -> None:
    """Started at (3, -2) heading 0.7 rad: the path read back is the commanded circle from the origin along +x."""
    from gmloco.eval.metrics.locomotion import circular_path
    from gmloco.eval.report.figures_paths import recorded_path

    n, dt = 200, 0.02
    rec = _record(tmp_path, "dry_sand__circle__v1.5", _circle_episode(1.5, 0.75, 0.7, (3.0, -2.0), n, dt), "tilt")
    p = recorded_path(rec)
    assert p.end_reason == "tilt"
    assert p.speed == pytest.approx(1.5) and p.yaw_rate == pytest.approx(0.75) and p.dt == pytest.approx(dt)
    expected, _ = circular_path(1.5, 0.75, (n - 1) * dt, dt)
    np.testing.assert_allclose(p.xy, expected, atol=1e-6)
    assert p.xy[1, 1] > 0.0  # a left turn bends to +y in the start frame


def test_figures_are_drawn_per_run_and_per_cell(tmp_path: Path) -> None:
    """Recordings parse by name and speed; a run's figures include the paths; paper_tables draws one per cell."""
    from gmloco.eval.report.figures_mpm import write_figures
    from gmloco.eval.report.figures_paths import recordings_by_cell

    run = tmp_path / "run"
    for v in (2.0, 1.0):
        _record(run, f"dry_sand__circle__v{v:g}", _circle_episode(v, v / 2.0, 0.0, (0.0, 0.0), 60, 0.02))
    (run / "recordings" / "notes.mcap").write_bytes(b"")  # a name that does not parse is skipped
    other = tmp_path / "other_share"
    _record(other, "dry_sand__circle__v1", _circle_episode(1.0, 0.5, 0.0, (0.0, 0.0), 60, 0.02))
    _record(other, "dry_sand__circle__v3", _circle_episode(3.0, 1.5, 0.0, (0.0, 0.0), 60, 0.02))
    two = recordings_by_cell([run, other])  # v1 from the first folder, v3 only in the second
    assert [f.parent.parent.name for f in two["dry_sand", "circle"]] == ["run", "run", "other_share"]
    cells = recordings_by_cell([run])
    assert list(cells) == [("dry_sand", "circle")]
    assert [f.stem for f in cells["dry_sand", "circle"]] == ["dry_sand__circle__v1", "dry_sand__circle__v2"]
    row = {"terrain": "dry_sand", "scenario": "circle", "speed": 1.0, "success": False, "vel_error": 0.1}
    paths = write_figures([row], run, "p", episode_s=2.0)
    assert (run / "fig_mpm_paths.png") in paths and (run / "fig_mpm_paths.png").stat().st_size > 0
    # the tables' view: one figure per cell with a panel per policy
    from gmloco.eval.report.paper_tables import _path_figures

    summaries = {"p": [{"cfg": {"episode_s": 2.0}}]}
    (tmp_path / "tables").mkdir()
    out = _path_figures({"p": [run]}, summaries, tmp_path / "tables")
    assert [f.name for f in out] == ["fig_paths_dry_sand_circle.png"] and out[0].stat().st_size > 0


def test_a_damaged_recording_costs_the_figure_not_the_run(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A recording without odometry (not an episode): the speed figure is still written, the paths one is skipped."""
    from gmloco.eval.report.figures_mpm import write_figures
    from gmloco.eval.report.figures_paths import recorded_path

    run = tmp_path / "run"
    ep = _circle_episode(1.0, 0.5, 0.0, (0.0, 0.0), 30, 0.02)
    rec = _record(run, "dry_sand__circle__v1", ep)
    rec.write_bytes(rec.read_bytes()[:200])  # cut inside the header: nothing decodable
    with pytest.raises((KeyError, ValueError, OSError)):
        recorded_path(rec)
    row = {"terrain": "dry_sand", "scenario": "circle", "speed": 1.0, "success": False, "vel_error": 0.1}
    paths = write_figures([row], run, "p", episode_s=1.0)
    assert [p.name for p in paths] == ["fig_mpm_speed_sweep.png"]
    assert "fig_mpm_paths.png skipped" in capsys.readouterr().err
