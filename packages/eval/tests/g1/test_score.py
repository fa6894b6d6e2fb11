# SPDX-License-Identifier: Apache-2.0
"""Scoring of hand-made episode logs: success, tracking, swings, window exits, layers; and their MCAP."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from gmloco.eval.g1.config import EpisodeSpec, G1EvalCfg, Scenario
from gmloco.eval.g1.score import score_episode


def _log(xy: np.ndarray, vxy: np.ndarray, z: np.ndarray, dt: float, wz: float = 0.0) -> dict:
    """Upright base (identity quaternion, x y z w layout) along ``xy``; feet carrying m g."""
    n = len(xy)
    q = np.zeros((n, 7))
    q[:, :2], q[:, 2], q[:, 6] = xy, z, 1.0
    qd = np.zeros((n, 6))
    qd[:, :2], qd[:, 5] = vxy, wz
    force = np.zeros((n, 2, 3))
    force[:, :, 2] = 0.5 * 30.0 * 9.81
    return {"dt": dt, "base_q": q, "base_qd": qd, "foot_force": force, "sinkage": np.full(n, 0.02),
            "foot_sinkage": np.full((n, 2), 0.02), "start_xy": np.zeros(2), "robot_mass": 30.0, "particles": 1, "build_s": 0.0, "sim_s": 1.0,
            "frames": n}  # fmt: skip


def test_perfect_straight_walk_succeeds() -> None:
    """Walking exactly at 1 m/s for 2 s: success, zero tracking and path errors, support ratio 1."""
    cfg = replace(G1EvalCfg(), episode_s=2.0)
    dt, n = 0.02, 100
    t = (np.arange(n) + 1) * dt
    log = _log(np.stack([t, 0 * t], 1), np.tile([1.0, 0.0], (n, 1)), np.full(n, 0.7), dt)
    row = score_episode(EpisodeSpec("dry_sand", Scenario.straight, 1.0, 0), cfg, log)
    assert row["success"] and row["reason"] == "success"
    assert row["finished_at_s"] is not None and row["finished_at_s"] <= 2.0 * (1 - cfg.course_slack) + 1e-9
    assert math.isclose(row["vel_error"], 0.0, abs_tol=1e-12) and math.isclose(row["yaw_error"], 0.0)
    assert math.isclose(row["heading_error_deg"], 0.0)
    assert row["path_error"] < 0.011  # half a sample spacing at most
    assert math.isclose(row["support_ratio"], 1.0) and math.isclose(row["max_sinkage"], 0.02)
    assert math.isclose(row["mean_sinkage"], 0.02)
    assert row["swings"] == 0 and math.isnan(row["swing_apex"])  # both feet loaded throughout: no swing


def test_swing_clearance_of_a_stepping_foot() -> None:
    """One foot lifts 6 cm out of a 2 cm footprint every 20 steps: apex 4 cm above the surface, lift 6 cm."""
    cfg = replace(G1EvalCfg(), episode_s=2.0)
    dt, n = 0.02, 100
    t = (np.arange(n) + 1) * dt
    log = _log(np.stack([t, 0 * t], 1), np.tile([1.0, 0.0], (n, 1)), np.full(n, 0.7), dt)
    swing = (np.arange(n) % 20) >= 10
    log["foot_force"][swing, 0, 2] = 0.0
    log["foot_sinkage"][swing, 0] = -0.04
    row = score_episode(EpisodeSpec("dry_sand", Scenario.straight, 1.0, 0), cfg, log)
    assert row["swings"] == 4  # the fifth swing is still open when the log ends
    assert math.isclose(row["swing_apex"], 0.04) and math.isclose(row["swing_lift"], 0.06)


def test_a_sole_outside_the_sand_window_flags_the_episode() -> None:
    """A sole outside its window from step 30 of a 100-step walk: exit at 0.6 s, flagged; in the last 0.25 s: not.

    The soles' reach is the largest over the samples with a sole near the sand (NaN samples skipped).
    """
    cfg = replace(G1EvalCfg(), episode_s=2.0)
    dt, n = 0.02, 100
    t = (np.arange(n) + 1) * dt
    log = _log(np.stack([t, 0 * t], 1), np.tile([1.0, 0.0], (n, 1)), np.full(n, 0.7), dt)
    row = score_episode(EpisodeSpec("dry_sand", Scenario.straight, 1.0, 0), cfg, log)
    assert row["window_exit_s"] is None and not row["window_exit_early"]  # a log without the field: no exit
    log["sole_out"] = np.zeros(n)
    log["sole_out"][30:33] = 4
    row = score_episode(EpisodeSpec("dry_sand", Scenario.straight, 1.0, 0), cfg, log)
    assert math.isclose(row["window_exit_s"], 0.6) and row["window_exit_early"]
    log["sole_out"][:] = 0
    log["sole_out"][n - 10 :] = 2  # during the last 0.2 s of the episode: the fall's last moments, not flagged
    log["sole_reach"] = np.tile([0.3, 0.15, 0.2], (n, 1))
    log["sole_reach"][40] = [0.45, 0.1, 0.25]
    log["sole_reach"][50] = np.nan  # both soles in the air
    row = score_episode(EpisodeSpec("dry_sand", Scenario.straight, 1.0, 0), cfg, log)
    assert math.isclose(row["window_exit_s"], (n - 10) * dt) and not row["window_exit_early"]
    assert (row["sole_behind_m"], row["sole_ahead_m"], row["sole_side_m"]) == (0.45, 0.15, 0.25)


def test_standing_still_times_out_and_fall_fails() -> None:
    """Standing at 1 m/s command: timeout with velocity error 1; base at 0.1 m from step 10: base-height failure."""
    cfg = replace(G1EvalCfg(), episode_s=2.0)
    dt, n = 0.02, 100
    xy, v = np.zeros((n, 2)), np.zeros((n, 2))
    row = score_episode(EpisodeSpec("dry_sand", Scenario.straight, 1.0, 0), cfg, _log(xy, v, np.full(n, 0.7), dt))
    assert (row["success"], row["reason"]) == (False, "timeout") and math.isclose(row["vel_error"], 1.0)
    z = np.full(n, 0.7)
    z[10:] = 0.1
    row = score_episode(EpisodeSpec("dry_sand", Scenario.straight, 1.0, 0), cfg, _log(xy, v, z, dt))
    assert (row["reason"], row["alive_s"]) == ("base_height", 10 * dt)


def test_episode_mcap_round_trip(tmp_path: Path) -> None:
    """A hand-made 1 s episode written as MCAP reads back: joints reordered to the SDK order, contact, odometry."""
    from gmloco.deploy.logs import G1_JOINT_NAMES, read_log
    from gmloco.eval.g1.record import write_episode_mcap

    n, dt = 50, 0.02
    names = list(reversed(G1_JOINT_NAMES))  # policy order differs from the SDK order
    jq = np.tile(np.arange(29, dtype=float) * 0.01, (n, 1))  # joint names[i] at 0.01 i rad
    force = np.zeros((n, 2, 3))
    force[:, 0, 2] = 300.0  # left foot loaded above the 40 N threshold, right foot in the air
    log = _log(np.stack([np.arange(n) * dt, np.zeros(n)], 1), np.tile([1.0, 0.0], (n, 1)), np.full(n, 0.7), dt)
    ep = {**log, "joint_q": jq, "joint_qd": np.zeros((n, 29)), "target": jq, "action": np.zeros((n, 29)),
          "foot_force": force, "foot_sinkage": np.full((n, 2), 0.01), "command": (1.0, 0.0, 0.0),
          "joint_names": names, "kp": np.full(29, 40.0), "kd": np.full(29, 2.0)}  # fmt: skip
    path = write_episode_mcap(tmp_path / "ep.mcap", ep, {"policy": "p", "material": "dry_sand"})
    lg = read_log(path)
    t, q = lg.signal("lowstate.q", names[3])
    np.testing.assert_allclose(t[:2], [0.0, dt], atol=1e-9)
    np.testing.assert_allclose(q, 0.03)
    _, contact = lg.signal("sim.in_contact")
    assert contact[:, 0].all() and not contact[:, 1].any()
    _, pos = lg.signal("odom.position")
    np.testing.assert_allclose(pos[-1, :2], [(n - 1) * dt, 0.0], atol=1e-9)
    # at constant velocity the specific force is gravity: +9.81 m/s^2 on the IMU z axis
    _, acc = lg.signal("imu.accelerometer")
    np.testing.assert_allclose(acc[:, 2], 9.81, atol=1e-6)
    assert lg.metadata.contact_model == "mpm" and lg.metadata.material == "dry_sand"
    assert lg.metadata.extra["derived_signals"] == "imu.accelerometer"  # the mismatch replay leaves it out
    assert not lg.has("student.eta")  # no decoded eta given: no topic
    eta = np.linspace(0.1, 0.4, n)
    eta[:3] = np.nan  # e.g. a policy step before the student's history is read: not written
    lg = read_log(write_episode_mcap(tmp_path / "eta.mcap", ep | {"eta": eta}, {"policy": "p"}))
    t_eta, eta_back = lg.signal("student.eta")
    np.testing.assert_allclose(t_eta, np.arange(3, n) * dt, atol=1e-9)
    np.testing.assert_allclose(eta_back.ravel(), eta[3:], rtol=1e-6)


def test_transition_course_per_medium(tmp_path: Path) -> None:
    """A walk over basalt -> dry sand -> poppy seed: decoded eta and swing apex / lift per medium, table and figure.

    x = 1.2 t over 10 s; media change at x = 4 and 7 m (``terrain_cfg("transition")``). Foot 0 stands 10 steps at
    0 / -2 / -6 cm and swings 10 steps at +4 / +3 / +1 cm on each medium; eta reads 0.5 / 0.09 / 0.02.
    """
    from gmloco.eval.mpm.window_terrain import terrain_cfg, terrain_layer
    from gmloco.eval.report.figures_mpm import write_figures
    from gmloco.eval.report.tables_mpm import table_transition, write_tables

    cfg = replace(G1EvalCfg(), episode_s=10.0)
    dt, n = 0.02, 500
    t = (np.arange(n) + 1) * dt
    log = _log(np.stack([1.2 * t, 0 * t], 1), np.tile([1.2, 0.0], (n, 1)), np.full(n, 0.7), dt)
    terrain = terrain_cfg("transition")
    layer = terrain_layer(terrain, 1.2 * t)
    stance, apex, eta = np.array([0.0, -0.02, -0.06]), np.array([0.04, 0.03, 0.01]), np.array([0.5, 0.09, 0.02])
    swing = (np.arange(n) % 20) >= 10
    log["foot_force"][swing, 0, 2] = 0.0
    log["foot_sinkage"][:, 0] = -np.where(swing, apex[layer], stance[layer])
    log |= {"terrain_cfg": terrain, "eta": eta[layer]}
    row = score_episode(EpisodeSpec("transition", Scenario.straight, 1.2, 0), cfg, log)
    layers = {entry["medium"]: entry for entry in row["layers"]}
    assert list(layers) == list(terrain.materials) and sum(e["steps"] for e in layers.values()) == n
    for k, medium in enumerate(terrain.materials):
        entry = layers[medium]
        assert entry["swings"] >= 3 and np.isclose(entry["eta_mean"], eta[k])
        assert np.isclose(entry["swing_apex"], apex[k]) and np.isclose(entry["swing_lift"], apex[k] - stance[k])
    table = table_transition([row])
    assert [r[1] for r in table] == list(terrain.materials)
    np.testing.assert_allclose([r[4] for r in table], 100 * apex)
    paths = write_tables([row], tmp_path, "p") + write_figures([row], tmp_path, "p")
    assert {p.name for p in paths} >= {"table_transition.md", "table_transition.csv", "fig_mpm_transition.png"}
    # a single-medium terrain has no per-medium stats and writes no transition outputs
    flat_log = _log(np.stack([1.2 * t, 0 * t], 1), np.tile([1.2, 0.0], (n, 1)), np.full(n, 0.7), dt)
    flat = score_episode(
        EpisodeSpec("dry_sand", Scenario.straight, 1.2, 0), cfg, flat_log | {"terrain_cfg": terrain_cfg("dry_sand")}
    )
    assert flat["layers"] is None and table_transition([flat]) == []


def test_a_window_exit_is_blamed_on_a_turn_or_on_the_reach() -> None:
    """Soles within the window's extent along the heading: the robot turned; beyond it: the window is too small.

    Hand-made walk: the heading turns steadily to 60 degrees; a sole leaves the (1.4 x 0.6 m, lead 0.2) window at
    step 30. With the soles 0.4 m behind and 0.2 m beside the pelvis (inside 0.5 / 0.3 m) the cause is the turn;
    0.6 m behind (beyond 0.5 m) it is the reach; a static bed never turns.
    """
    cfg = replace(G1EvalCfg(), episode_s=2.0)
    dt, n = 0.02, 100
    t = (np.arange(n) + 1) * dt
    log = _log(np.stack([t, 0 * t], 1), np.tile([1.0, 0.0], (n, 1)), np.full(n, 0.7), dt)
    yaw = np.radians(np.linspace(0.0, 60.0, n))
    log["base_q"][:, 5], log["base_q"][:, 6] = np.sin(0.5 * yaw), np.cos(0.5 * yaw)
    log["sole_out"] = np.zeros(n)
    log["sole_out"][30:] = 1
    log["sole_reach"] = np.tile([0.4, 0.2, 0.2], (n, 1))
    spec = EpisodeSpec("dry_sand", Scenario.straight, 1.0, 0)
    row = score_episode(spec, cfg, log)
    assert math.isclose(row["heading_turn_deg"], 60.0, rel_tol=1e-6)
    assert row["window_exit_cause"] == "turn" and row["window_exit_turn"] and row["window_exit_early"]
    log["sole_reach"][30] = [0.6, 0.2, 0.2]
    row = score_episode(spec, cfg, log)
    assert row["window_exit_cause"] == "reach" and not row["window_exit_turn"]
    log["sole_reach"][30] = [0.4, 0.2, 0.29]  # within the 2 cm margin of the side: counted as beyond
    assert score_episode(spec, cfg, log)["window_exit_cause"] == "reach"
    log["sole_reach"][30] = [0.4, 0.2, 0.2]
    static = replace(cfg, window=replace(cfg.window, moving=False))
    assert score_episode(spec, static, log)["window_exit_cause"] == "reach"
    del log["sole_out"]
    row = score_episode(spec, cfg, log)
    assert row["window_exit_cause"] is None and not row["window_exit_turn"]


def test_heading_turn_wraps_around() -> None:
    """A heading going from 170 to -170 degrees turned 20 degrees, not 340; only alive samples count."""
    from gmloco.eval.g1.score import heading_turn_deg

    yaw = np.radians([170.0, 180.0, -170.0, 90.0])
    assert math.isclose(heading_turn_deg(yaw, 3), 20.0, rel_tol=1e-9)
    assert math.isclose(heading_turn_deg(yaw, 4), 80.0, rel_tol=1e-9)
