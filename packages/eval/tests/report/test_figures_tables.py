# SPDX-License-Identifier: Apache-2.0
"""A figure per MPM table and the adaptation figure: swing apexes by hand, recordings read back, figures rendered."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("matplotlib")
pytest.importorskip("mcap")

from gmloco.eval.report.figures_tables import adaptation_trace, swing_apexes
from gmloco.eval.report.paper_tables import combine

SETTING = {"solver": {"voxel_size": 0.03}, "window": {"length": 1.4}, "bed_depth": 0.3, "episode_s": 10.0,
           "failure": {"max_tilt": 0.785}, "course_slack": 0.2, "circle_radius": 2.0}  # fmt: skip


def test_swing_apexes_hand_computed() -> None:
    """Contact T T F F F T T F F: one completed swing (samples 2-4), apex 0.10 m at 3; the open swing is left out."""
    height = np.array([0.0, 0.0, 0.05, 0.10, 0.08, 0.0, 0.0, 0.02, 0.03])
    contact = np.array([1, 1, 0, 0, 0, 1, 1, 0, 0], dtype=bool)
    assert swing_apexes(height, contact) == [(3, 0.10)]
    assert swing_apexes(height, contact, min_steps=4) == []  # a 3-sample swing is flicker at min_steps 4


def _episode_log(eta: bool, n: int = 50, dt: float = 0.02) -> dict[str, Any]:
    """A 1 m/s straight walk along x: the left sole lifts 0.1 m over samples 10-19, sinkage 0.02 m otherwise."""
    from gmloco.deploy.logs import G1_JOINT_NAMES

    a = len(G1_JOINT_NAMES)
    q = np.zeros((n, 7))
    q[:, 0], q[:, 2], q[:, 6] = np.arange(n) * dt, 0.75, 1.0
    qd = np.zeros((n, 6))
    qd[:, 0] = 1.0
    force = np.zeros((n, 2, 3))
    force[:, :, 2] = 300.0
    sink = np.full((n, 2), 0.02)
    force[10:20, 0, 2], sink[10:20, 0] = 0.0, -0.1  # the left foot's swing, 10 cm above the surface
    log = {"dt": dt, "base_q": q, "base_qd": qd, "joint_q": np.zeros((n, a)), "joint_qd": np.zeros((n, a)),
           "target": np.zeros((n, a)), "action": np.zeros((n, a)), "foot_force": force, "foot_sinkage": sink,
           "command": (1.0, 0.0, 0.0), "joint_names": list(G1_JOINT_NAMES), "kp": np.ones(a), "kd": np.ones(a)}  # fmt: skip
    if eta:
        log["eta"] = np.linspace(0.3, 0.1, n)
    return log


def test_adaptation_trace_reads_a_recording(tmp_path: Path) -> None:
    """Course position, sole heights (minus the logged sinkage), the swing's apex and the decoded eta come back."""
    from gmloco.eval.g1.record import write_episode_mcap

    path = write_episode_mcap(tmp_path / "transition__straight__v1.mcap", _episode_log(eta=True),
                              {"policy": "p", "material": "transition"})  # fmt: skip
    tr = adaptation_trace(path)
    np.testing.assert_allclose(tr.x, np.arange(50) * 0.02, atol=1e-9)
    np.testing.assert_allclose(tr.height[:, 1], -0.02)
    assert tr.speed == 1.0 and tr.eta is not None
    np.testing.assert_allclose(tr.eta, np.linspace(0.3, 0.1, 50), atol=1e-6)
    assert swing_apexes(tr.height[:, 0], tr.contact[:, 0]) == [(10, pytest.approx(0.1))]
    bare = write_episode_mcap(tmp_path / "bare.mcap", _episode_log(eta=False), {"policy": "p", "material": "m"})
    assert adaptation_trace(bare).eta is None


def _run(root: Path, name: str, terrain: str, scenario: str, layers: bool = False) -> Path:
    """A g1_eval-shaped run folder: 4 episodes (2 successes) of one cell at 1 and 2 m/s, transition layers if asked."""
    d = root / name
    (d / "recordings").mkdir(parents=True)
    policy = f"artifacts/{name.split('_')[0]}/policy.onnx"
    (d / "summary.json").write_text(json.dumps({"cfg": SETTING, "policy": policy}))
    media = [("basalt", 0.3, 0.08), ("dry_sand", 0.1, 0.10), ("poppy_seed", 0.05, 0.14)]
    rows = [{"terrain": terrain, "scenario": scenario, "speed": 1.0 + k % 2, "success": k < 2, "alive_s": 10.0,
             "vel_error": 0.2, "heading_error_deg": 2.0, "yaw_error": 0.1, "path_error": 0.3, "mean_sinkage": 0.05,
             "swing_apex": 0.1, "swing_lift": 0.12,
             "layers": [{"medium": m, "steps": 100, "swings": 8, "eta_mean": e, "swing_apex": h, "swing_lift": h + 0.02}
                        for m, e, h in media] if layers else None}
            for k in range(4)]  # fmt: skip
    (d / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    return d


def test_table_figures_render_from_a_small_fixture(tmp_path: Path) -> None:
    """Two policies, straight and circle, one transition run with a recording: every table's figure is written."""
    from gmloco.eval.g1.record import write_episode_mcap

    runs = [("td", _run(tmp_path, "td_s", "dry_sand", "straight")), ("td", _run(tmp_path, "td_c", "dry_sand", "circle")),
            ("td", _run(tmp_path, "td_t", "transition", "straight", layers=True)),
            ("rigid", _run(tmp_path, "rigid_s", "dry_sand", "straight"))]  # fmt: skip
    write_episode_mcap(tmp_path / "td_t" / "recordings" / "transition__straight__v1.mcap", _episode_log(eta=True),
                       {"policy": "td", "material": "transition"})  # fmt: skip
    out = tmp_path / "tables"
    summary = combine(runs, out, episodes=4)
    names = ["fig_table_terrains.png", "fig_table_speeds.png", "fig_table_ablation.png", "fig_table_per_terrain.png",
             "fig_table_transition.png", "fig_adaptation_td.png"]  # fmt: skip
    for name in names:
        assert name in summary["figures"] and (out / name).stat().st_size > 10_000, name
    assert "fig_adaptation_rigid.png" not in summary["figures"]  # no transition walk: no adaptation figure
