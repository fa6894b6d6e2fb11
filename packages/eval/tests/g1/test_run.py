# SPDX-License-Identifier: Apache-2.0
"""Episode bookkeeping and scoring of the MPM evaluation on hand-made trajectories (no simulation)."""

from __future__ import annotations

import json
import math
import time
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace
from typing import ClassVar, Literal

import numpy as np
import pytest

from gmloco.eval.g1.cell import run_cell
from gmloco.eval.g1.config import EpisodeSpec, G1EvalCfg, episode_batches, episode_specs
from gmloco.eval.g1.scene import LOG_FIELDS
from gmloco.eval.g1.score import score_episode
from gmloco.eval.g1.timebox import cell_minutes_left
from gmloco.eval.metrics.episodes import exit_in_fall, summarize
from gmloco.eval.mpm.window import SandWindowCfg
from gmloco.eval.report.tables_mpm import table_speeds, table_terrains


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
    row = score_episode(EpisodeSpec("dry_sand", "straight", 1.0, 0), cfg, log)
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
    row = score_episode(EpisodeSpec("dry_sand", "straight", 1.0, 0), cfg, log)
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
    row = score_episode(EpisodeSpec("dry_sand", "straight", 1.0, 0), cfg, log)
    assert row["window_exit_s"] is None and not row["window_exit_early"]  # a log without the field: no exit
    log["sole_out"] = np.zeros(n)
    log["sole_out"][30:33] = 4
    row = score_episode(EpisodeSpec("dry_sand", "straight", 1.0, 0), cfg, log)
    assert math.isclose(row["window_exit_s"], 0.6) and row["window_exit_early"]
    log["sole_out"][:] = 0
    log["sole_out"][n - 10 :] = 2  # during the last 0.2 s of the episode: the fall's last moments, not flagged
    log["sole_reach"] = np.tile([0.3, 0.15, 0.2], (n, 1))
    log["sole_reach"][40] = [0.45, 0.1, 0.25]
    log["sole_reach"][50] = np.nan  # both soles in the air
    row = score_episode(EpisodeSpec("dry_sand", "straight", 1.0, 0), cfg, log)
    assert math.isclose(row["window_exit_s"], (n - 10) * dt) and not row["window_exit_early"]
    assert (row["sole_behind_m"], row["sole_ahead_m"], row["sole_side_m"]) == (0.45, 0.15, 0.25)


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


def test_one_turning_window_serves_straight_and_circle() -> None:
    """The default window turns: the circle keeps it, lanes spaced by its diagonal plus twice its lead (any heading).

    1.4 x 0.6 m, lead 0.2 m: hypot = 1.5232 m, + 0.4 = 1.9232 m; the circle adds its 4 m diameter.
    """
    from gmloco.eval.g1.lanes import window_and_lanes

    cfg = G1EvalCfg()
    straight, lane_s = window_and_lanes([EpisodeSpec("dry_sand", "straight", 1.0, 0)], cfg)
    circle, lane_c = window_and_lanes([EpisodeSpec("dry_sand", "circle", 1.0, 0)], cfg)
    assert straight == circle == cfg.window and cfg.window.turn_with_robot
    span = math.hypot(1.4, 0.6) + 0.4
    assert lane_s == pytest.approx(span + cfg.lane_gap)
    assert lane_c == pytest.approx(span + 2.0 * cfg.circle_radius + cfg.lane_gap)


def test_a_window_on_the_grid_axes_becomes_a_square_on_a_circle() -> None:
    """A window that does not turn: on a circle it is max(length, width) square; straight it is as set."""
    from gmloco.eval.g1.lanes import window_and_lanes

    cfg = replace(G1EvalCfg(), window=replace(G1EvalCfg().window, turn_with_robot=False))
    straight, lane_s = window_and_lanes([EpisodeSpec("dry_sand", "straight", 1.0, 0)], cfg)
    circle, lane_c = window_and_lanes([EpisodeSpec("dry_sand", "circle", 1.0, 0)], cfg)
    assert (straight.length, straight.width) == (cfg.window.length, cfg.window.width)
    side = max(cfg.window.length, cfg.window.width)
    assert (circle.length, circle.width, circle.lead) == (side, side, cfg.window.lead)
    assert lane_c == side + 2.0 * cfg.circle_radius + cfg.lane_gap and lane_s == cfg.window.width + cfg.lane_gap


def test_standing_still_times_out_and_fall_fails() -> None:
    """Standing at 1 m/s command: timeout with velocity error 1; base at 0.1 m from step 10: base-height failure."""
    cfg = replace(G1EvalCfg(), episode_s=2.0)
    dt, n = 0.02, 100
    xy, v = np.zeros((n, 2)), np.zeros((n, 2))
    row = score_episode(EpisodeSpec("dry_sand", "straight", 1.0, 0), cfg, _log(xy, v, np.full(n, 0.7), dt))
    assert (row["success"], row["reason"]) == (False, "timeout") and math.isclose(row["vel_error"], 1.0)
    z = np.full(n, 0.7)
    z[10:] = 0.1
    row = score_episode(EpisodeSpec("dry_sand", "straight", 1.0, 0), cfg, _log(xy, v, z, dt))
    assert (row["reason"], row["alive_s"]) == ("base_height", 10 * dt)


def test_episode_specs_batches_summary_and_tables() -> None:
    """2 terrains x 1 scenario x 3 episodes, speeds cycled; batches stay in a cell; summary and tables agree."""
    cfg = replace(G1EvalCfg(), terrains=("dry_sand", "poppy_seed"), num_episodes=3, speeds=(1.0, 2.0))
    specs = episode_specs(cfg)
    assert [s.speed for s in specs[:3]] == [1.0, 2.0, 1.0] and len({s.key for s in specs}) == 6
    # batches of 2: [ds0, ds1], [ds2], [ps0, ps1], [ps2] (a batch never mixes terrains)
    assert [[s.index for s in b] for b in episode_batches(specs, 2)] == [[0, 1], [2], [0, 1], [2]]
    rows = [{"terrain": s.terrain, "scenario": s.scenario, "speed": s.speed, "success": s.index == 0,
             "vel_error": 0.1 * s.index, "heading_error_deg": 3.0, "yaw_error": 0.0, "path_error": 0.0,
             "support_ratio": 1.0,
             "max_sinkage": 0.01, "mean_sinkage": 0.005, "swing_apex": 0.02 * s.index,
             "swing_lift": float("nan") if s.index else 0.06, "window_exit_early": s.index == 2,
             "window_exit_turn": False}
            for s in specs]  # fmt: skip
    m = summarize(rows)
    assert math.isclose(m["all/success_rate"], 1 / 3) and m["all/num_episodes"] == 6
    assert m["all/success_lo95"] < 1 / 3 < m["all/success_hi95"]  # 2 of 6: the Wilson interval holds the rate
    assert math.isclose(m["dry_sand/straight/v1/vel_error"], 0.1) and m["poppy_seed/straight/v2/num_episodes"] == 1
    # table: dry sand success 1/3 = 33.3 %, velocity error mean(0, 0.1, 0.2) = 0.1 m/s, heading error 3 degrees,
    # sinkage 0.5 cm, swing apex
    # mean(0, 2, 4) = 2 cm, lift 6 cm (episodes without a finished swing, NaN, are left out of the mean); one of
    # the three episodes had a sole outside its sand window early: 33.3 %, not by a turn: 0 %, not with a fall: 0 %
    t = table_terrains(rows, "p")
    assert t[0][:4] == ["p", "dry_sand", "straight", 3]
    np.testing.assert_allclose(t[0][4:5] + t[0][7:], [100 / 3, 0.1, 3.0, 0.0, 0.0, 0.5, 2.0, 6.0, 100 / 3, 0.0, 0.0])
    assert math.isclose(m["all/window_exit_early"], 1 / 3)
    assert t[0][5] < 100 / 3 < t[0][6]  # the 95 % interval of 1 success in 3 episodes holds the rate
    header, body = table_speeds(rows)
    # v = 1: episodes 0 (success) and 2 (fail) -> 50 %; v = 2: episode 1 (fail) -> 0 %
    assert header[2:] == ["v=1 m/s", "v=2 m/s"] and body[0][2:] == [50.0, 0.0]


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


class _LaneScene:
    """Stand-in for ``G1MpmScene`` in ``run_cell``: 4 frames per policy step, one upright robot per lane.

    The robot of the episode with spec index k tips over (pelvis 0.1 m) at its own policy step ``FALLS[k]``.
    """

    FALLS: ClassVar[dict[int, int]] = {}
    made: ClassVar[list[_LaneScene]] = []
    TICK: ClassVar[float] = 0.0
    """Seconds a frame of one lane advances ``now`` (the stand-in clock of the time-box tests)."""
    now: ClassVar[list[float]] = [0.0]

    def __init__(self, cfg: object, policy: object) -> None:
        n = cfg.num_robots  # type: ignore[attr-defined]
        self.frames_per_policy, self.frame_dt, self.frame, self.n = 4, 0.005, 0, n
        self.lane_y = np.arange(n) * cfg.lane_spacing  # type: ignore[attr-defined]
        self.commands = np.array(cfg.commands, dtype=float)  # type: ignore[attr-defined]
        self.spec = SimpleNamespace(joint_names=["j"], kp=np.ones(1), kd=np.ones(1))
        self.robot_mass, self.particle_count, self.wall_time, self.frames_per_second = 30.0, 1, 1.0, 1.0
        self.events: list[str] = []  # "sync" / "check": the order of device waits and grid checks
        self.mpm = SimpleNamespace(check_sparse_grid_rebuild_status=lambda: self.events.append("check"))
        self.lane_episode, self.lane_step = list(range(n)), [0] * n
        self.resets: list[tuple[list[int], list[int], int]] = []
        self.retired: list[tuple[list[int], int]] = []
        self.base_q: list[np.ndarray] = []
        for name in LOG_FIELDS[1:]:  # the scene's per-robot logs (base_q typed above: run_cell reads it)
            setattr(self, name, [])
        _LaneScene.made.append(self)

    def capture(self) -> None:
        pass

    def sync(self) -> None:
        self.events.append("sync")

    def step(self) -> None:
        if self.frame % self.frames_per_policy == 0:
            q = np.zeros((self.n, 7))
            q[:, 6] = 1.0
            for r in range(self.n):
                fall = self.FALLS.get(self.lane_episode[r])
                q[r, 2] = 0.1 if fall is not None and self.lane_step[r] >= fall else 0.7
                self.lane_step[r] += 1
            sample = {"base_q": q, "base_qd": np.zeros((self.n, 6)), "foot_force": np.full((self.n, 2, 3), 150.0),
                      "sinkage": np.full(self.n, 0.02), "foot_sinkage": np.full((self.n, 2), 0.02),
                      "eta": np.full(self.n, np.nan)}  # fmt: skip
            for name in LOG_FIELDS:
                getattr(self, name).append(sample.get(name, np.zeros((self.n, 1))))
        self.frame += 1
        _LaneScene.now[0] += self.TICK * self.n

    def retire_robots(self, robots: list[int]) -> None:
        self.retired.append((list(robots), len(self.base_q)))

    def reset_robots(self, robots: list[int], commands: list, seeds: list[int]) -> None:
        if robots:
            self.resets.append((list(robots), list(seeds), len(self.base_q)))
        for r, seed in zip(robots, seeds, strict=True):
            self.lane_episode[r], self.lane_step[r] = seed - 1, 0


class _Policy:
    num_robots = 2

    def reset(self, robots: object = None) -> None:
        pass


def _cell(monkeypatch: pytest.MonkeyPatch, falls: dict[int, int], **kw: object) -> tuple[G1EvalCfg, list[EpisodeSpec]]:
    import gmloco.eval.g1.scene as g1_scene

    monkeypatch.setattr(g1_scene, "G1MpmScene", _LaneScene)
    monkeypatch.setattr(_LaneScene, "FALLS", falls)
    monkeypatch.setattr(_LaneScene, "made", [])
    base = {"num_episodes": 5, "speeds": (1.0,), "episode_s": 0.2, "robots_per_batch": 2, "record_mcap": False}
    cfg = replace(G1EvalCfg(), **(base | kw))
    return cfg, episode_specs(cfg)


def test_a_fallen_lane_takes_the_next_episode(monkeypatch: pytest.MonkeyPatch) -> None:
    """5 episodes in 2 lanes of 10 policy steps; episode 0 tips over at its step 3.

    Lane 0: episode 0 ends with the failing sample (rows 0-3), then episodes 2 (rows 4-13) and 4 (14-23); lane 1:
    episodes 1 (0-9) and 3 (10-19). Each refill passes seed offset index + 1.
    """
    cfg, specs = _cell(monkeypatch, {0: 3})
    logs: list[dict] = []
    assert run_cell(specs, cfg, _Policy(), logs.append).finished
    assert [lg["spec"].index for lg in logs] == [0, 1, 2, 3, 4]
    assert [len(lg["base_q"]) for lg in logs] == [4, 10, 10, 10, 10]
    scene = _LaneScene.made[0]
    assert scene.resets == [([0], [3], 4), ([1], [4], 10), ([0], [5], 14)]
    assert scene.retired == [([1], 20)]  # lane 1 has no episode left while lane 0 walks episode 4 to row 24
    rows = [score_episode(lg["spec"], cfg, lg) for lg in logs]
    assert (rows[0]["reason"], rows[0]["alive_s"]) == ("base_height", 3 * 0.02)
    assert [r["reason"] for r in rows[1:]] == ["timeout"] * 4  # standing still at a 1 m/s command
    elapsed = [r["elapsed_s"] for r in rows]  # the wall clock since the first frame, in the order the ends came
    assert all(e >= 0.0 for e in elapsed) and elapsed == sorted(elapsed)
    assert [r["end_frame"] for r in rows] == [16, 40, 56, 80, 96]  # the scene's frame at each end (4 per step)
    # every grid check waits for the frames in flight through the scene's clock first (the square-window runs' clock fix)
    ev = scene.events
    assert ev.count("check") >= 5 and all(ev[i - 1] == "sync" for i, e in enumerate(ev) if e == "check")


def test_idle_lanes_keep_their_sand_when_asked(monkeypatch: pytest.MonkeyPatch) -> None:
    """retire_idle_lanes=False: the same episodes, no lane retired (the runs before ``retire_idle_lanes`` existed)."""
    cfg, specs = _cell(monkeypatch, {0: 3}, retire_idle_lanes=False)
    logs: list[dict] = []
    assert run_cell(specs, cfg, _Policy(), logs.append).finished
    assert [lg["spec"].index for lg in logs] == [0, 1, 2, 3, 4] and _LaneScene.made[0].retired == []


def test_minutes_left_counts_waves_of_lanes() -> None:
    """2 lanes with 10 and 40 steps left, 3 queued episodes of 100 steps, 4 frames per step at 2 frames/s.

    Lane A: 10 -> 110 -> 210; lane B: 40 -> 140; the last ends at step 210 = 840 frames = 420 s = 7 min.
    """
    assert cell_minutes_left([10, 40], 3, 100, 4, 2.0) == pytest.approx(7.0)
    assert cell_minutes_left([], 5, 100, 4, 2.0) == 0.0 and cell_minutes_left([1], 0, 100, 4, 0.0) == 0.0


def test_without_refill_lanes_idle_and_batches_get_their_own_solver(monkeypatch: pytest.MonkeyPatch) -> None:
    """refill=False: batches of 2, 2, 1 episodes, one scene each, no resets; the run writes all 5 episodes."""
    cfg, _ = _cell(monkeypatch, {0: 3}, refill=False)
    monkeypatch.setattr("gmloco.eval.g1.run.load_policy", lambda path, n=1: _Policy())
    monkeypatch.setattr("gmloco.eval.g1.cell.load_policy", lambda path, n=1: _Policy())
    _, complete = _run_in(cfg, monkeypatch)
    assert complete and len(_LaneScene.made) == 3 and all(not s.resets for s in _LaneScene.made)


def test_the_time_box_keeps_finished_episodes_only(monkeypatch: pytest.MonkeyPatch) -> None:
    """A deadline already passed: the cell stops at its first check (after one policy step), nothing handed out."""
    cfg, specs = _cell(monkeypatch, {})
    logs: list[dict] = []
    out = run_cell(specs, cfg, _Policy(), logs.append, deadline=time.perf_counter() - 1.0)
    assert (out.finished, out.stopped) == (False, "time_box")
    assert logs == [] and _LaneScene.made[0].frame == 4  # one policy step, then the check


def _time_boxed(
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    fit: bool,
    falls: dict[int, int] | None = None,
    prior_lane_s: float = 0.0,
    **kw: object,
) -> tuple[list[str], bool]:
    """The episodes logged and whether the run completed: 4 standing episodes of 40 frames in up to 4 lanes.

    A frame costs 0.25 s per lane on a stand-in clock; the time box is 30 s. The pre-build prior prices a frame at
    ``prior_lane_s`` per lane, built at once (0: every cell fits until its probe has measured it).
    """
    import gmloco.eval.g1.cell as g1_cell
    import gmloco.eval.g1.run as g1_eval
    import gmloco.eval.g1.timebox as g1_timebox
    from gmloco.eval.g1.cost import CellCost

    monkeypatch.setattr(g1_timebox, "prior_cost", lambda per_lane, n, sweeps: CellCost(n, prior_lane_s * n, 0.0))

    cfg, _ = _cell(monkeypatch, falls or {}, **({"num_episodes": 4, "robots_per_batch": 4} | kw), max_minutes=0.5,
                   fit_time_box=fit, out_dir=str(tmp_path))  # fmt: skip
    monkeypatch.setattr(_LaneScene, "TICK", 0.25)
    monkeypatch.setattr(_LaneScene, "now", [0.0])
    clock = SimpleNamespace(perf_counter=lambda: _LaneScene.now[0])
    for module in (g1_eval, g1_cell, g1_timebox):  # the run, its episode loop and the time box read one clock
        monkeypatch.setattr(module, "time", clock)
    monkeypatch.setattr(g1_eval, "FIT_PROBE_S", 4.0)
    monkeypatch.setattr(g1_eval, "load_policy", lambda path, n=1: _Policy())
    monkeypatch.setattr(g1_cell, "load_policy", lambda path, n=1: _Policy())
    monkeypatch.setattr(g1_eval, "write_outputs", lambda *a, **k: None)
    _, complete = g1_eval.run(cfg)
    log = tmp_path / "episodes.jsonl"
    return [json.loads(x)["key"] for x in (log.read_text().splitlines() if log.exists() else [])], complete


def test_a_cell_that_cannot_end_in_the_time_box_is_refit(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """4 lanes need 40 s for the 40 frames, 30 s are left: the cell stops after its 4 s probe and is rebuilt.

    With 2 lanes (predicted 6.6 + 9.35 n s <= 26 s) it ends at 24 s; 6 s then hold no further 40-frame walk.
    """
    keys, complete = _time_boxed(monkeypatch, tmp_path, fit=True)
    assert keys == ["dry_sand/straight/0", "dry_sand/straight/1"] and not complete
    assert [s.n for s in _LaneScene.made] == [4, 2] and _LaneScene.now[0] == pytest.approx(24.0)


def test_without_the_fit_the_time_box_drops_the_whole_cell(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """The same run with ``fit_time_box=False``: the 4-lane cell steps until the box and no episode is kept."""
    keys, complete = _time_boxed(monkeypatch, tmp_path, fit=False)
    assert keys == [] and not complete and [s.n for s in _LaneScene.made] == [4]


def test_a_freed_lane_takes_no_walk_that_cannot_end(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Refill stops when a whole walk would no longer end before the time box.

    6 episodes in 2 lanes (a frame 0.5 s), 30 s: episodes 0-1 fall at once and 2-3 take their lanes before the 4 s
    probe; those end at ~24 s, when a 40-frame walk (22 s with the margin) no longer fits, so 4-5 are left for the
    next call and the run stops at 24 s. Without the fit they start and are dropped at the box (30 s).
    """
    for fit, end in ((True, 24.0), (False, 30.0)):
        keys, complete = _time_boxed(monkeypatch, tmp_path / str(fit), fit, {0: 1, 1: 1}, num_episodes=6,
                                     robots_per_batch=2)  # fmt: skip
        assert [k[-1] for k in keys] == ["0", "1", "2", "3"] and not complete
        assert len(_LaneScene.made) == 1 and _LaneScene.now[0] == pytest.approx(end, abs=2.0)


def test_a_share_started_near_the_time_box_builds_only_the_lanes_the_prior_fits(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """Priced right before the build (0.25 s per lane a frame), 2 of the 4 lanes fit the 30 s: no 4-lane probe.

    44 frames with the margin at 0.25 (0.32 + 0.92 n) s <= 30 s holds for n = 2; the 2-lane cell's own probe agrees
    and it ends at 20 s; the next two 40-frame walks (22 s with the margin) do not fit the 10 s left.
    """
    keys, complete = _time_boxed(monkeypatch, tmp_path, fit=True, prior_lane_s=0.25)
    assert keys == ["dry_sand/straight/0", "dry_sand/straight/1"] and not complete
    assert [s.n for s in _LaneScene.made] == [2] and _LaneScene.now[0] == pytest.approx(20.0)


def test_a_share_whose_walk_cannot_end_is_not_built(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Priced at 1 s per lane a frame, one lane's 40-frame walk needs ~55 s of the 30 s left: nothing is built.

    The run stops before its first build, its episodes left for the next call.
    """
    keys, complete = _time_boxed(monkeypatch, tmp_path, fit=True, prior_lane_s=1.0)
    assert keys == [] and not complete and _LaneScene.made == [] and _LaneScene.now[0] == 0.0


def test_the_prior_prices_the_cell_build_cell_scene_builds() -> None:
    """The prior counts the batch's window as the scene solves it: the terrain's depth, one window for every walk."""
    from gmloco.eval.g1.cost import PRIOR_FRAME_S_AT_ZERO, PRIOR_FRAME_S_PER_MILLION
    from gmloco.eval.g1.timebox import cell_prior_cost

    cfg = replace(G1EvalCfg(), robots_per_batch=25, scenarios=("straight", "circle"))
    specs = episode_specs(cfg)
    straight = [s for s in specs if s.scenario == "straight"]
    circle = [s for s in specs if s.scenario == "circle"]
    per_lane = 94 * 40 * 20  # 1.4 x 0.6 m at 1.5 cm spacing, 30 cm deep
    cost = cell_prior_cost(straight, cfg)
    assert cost.lanes == 25
    assert cost.frame_s == pytest.approx(PRIOR_FRAME_S_AT_ZERO + PRIOR_FRAME_S_PER_MILLION * 25 * per_lane / 1e6)
    assert cell_prior_cost(circle, cfg).frame_s == cost.frame_s  # the turning window serves the circle as it is
    fixed = replace(cfg, window=replace(cfg.window, turn_with_robot=False))
    assert cell_prior_cost(circle, fixed).frame_s > cost.frame_s  # a window on the grid's axes: 94 x 94 on a circle


def _run_in(cfg: G1EvalCfg, monkeypatch: pytest.MonkeyPatch) -> tuple[dict, bool]:
    """``run`` in a temporary folder without tables and figures."""
    import tempfile

    import gmloco.eval.g1.run as g1_eval

    monkeypatch.setattr(g1_eval, "write_outputs", lambda *a, **k: None)
    with tempfile.TemporaryDirectory() as tmp:
        summary, complete = g1_eval.run(replace(cfg, out_dir=tmp))
        lines = (Path(tmp) / "episodes.jsonl").read_text().splitlines()
    assert len(lines) == cfg.num_episodes
    return summary, complete


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
    row = score_episode(EpisodeSpec("transition", "straight", 1.2, 0), cfg, log)
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
        EpisodeSpec("dry_sand", "straight", 1.2, 0), cfg, flat_log | {"terrain_cfg": terrain_cfg("dry_sand")}
    )
    assert flat["layers"] is None and table_transition([flat]) == []


def test_episodes_are_read_up_to_a_partial_last_line(tmp_path: Path) -> None:
    """A run killed mid-write leaves half a line: skipped (and cut off with repair); damage earlier is an error."""
    import json

    from gmloco.eval.metrics.episodes import read_episodes

    path = tmp_path / "episodes.jsonl"
    path.write_text(json.dumps({"key": "a"}) + "\n" + json.dumps({"key": "b"}) + "\n" + '{"key": "c", "succ')
    assert [r["key"] for r in read_episodes(path)] == ["a", "b"]
    assert path.read_text().count("\n") == 2  # untouched without repair
    assert [r["key"] for r in read_episodes(path, repair=True)] == ["a", "b"]
    assert path.read_text() == json.dumps({"key": "a"}) + "\n" + json.dumps({"key": "b"}) + "\n"
    path.write_text('{"key": "a"}\nnot json\n{"key": "b"}\n')
    with pytest.raises(ValueError, match=r"episodes\.jsonl:2: not an episode record"):
        read_episodes(path)


def _grid_scene(fail: bool, calls: list[int]) -> SimpleNamespace:
    """A scene whose MPM solver reports a grid overflow (``fail``) or none; each check is counted in ``calls``."""

    def check() -> None:
        calls.append(1)
        if fail:
            raise RuntimeError("overflow")

    return SimpleNamespace(mpm=SimpleNamespace(check_sparse_grid_rebuild_status=check))


def test_grid_overflow_invalidates_the_cell() -> None:
    """A sparse grid that outgrew its reserved cells: an error naming the capacity and --cell-capacity-factor."""
    from gmloco.eval.g1.cell import check_grid_capacity
    from gmloco.eval.mpm.box_scene import MpmSolverCfg

    calls: list[int] = []
    with pytest.raises(RuntimeError, match="--cell-capacity-factor") as info:
        check_grid_capacity(_grid_scene(True, calls), MpmSolverCfg(grid_type="sparse", max_active_cell_count=100))
    assert "100" in str(info.value) and "overflow" in str(info.value)
    assert isinstance(info.value.__cause__, RuntimeError) and calls == [1]


@pytest.mark.parametrize(("grid_type", "capacity"), [("sparse", -1), ("dense", 100)])
def test_grid_capacity_is_not_checked_without_a_reserved_sparse_grid(
    grid_type: Literal["sparse", "dense"], capacity: int
) -> None:
    """Newton's per-step allocation (capacity -1) or a dense grid: the overflow check is never asked."""
    from gmloco.eval.g1.cell import check_grid_capacity
    from gmloco.eval.mpm.box_scene import MpmSolverCfg

    calls: list[int] = []
    check_grid_capacity(_grid_scene(True, calls), MpmSolverCfg(grid_type=grid_type, max_active_cell_count=capacity))
    assert calls == []


def test_grid_within_capacity_passes() -> None:
    """A sparse grid inside its reserved cells: checked once, no error."""
    from gmloco.eval.g1.cell import check_grid_capacity
    from gmloco.eval.mpm.box_scene import MpmSolverCfg

    calls: list[int] = []
    check_grid_capacity(_grid_scene(False, calls), MpmSolverCfg(grid_type="sparse", max_active_cell_count=100))
    assert calls == [1]


def test_grid_capacity_pads_without_changing_the_walk() -> None:
    """1.5x and 3x the windows' cells reserved: the same pelvis trajectory (the capacity only pads the solve)."""
    from gmloco.eval.g1.cell import build_cell_scene
    from gmloco.eval.g1.policy import load_policy

    base = G1EvalCfg()
    final = {}
    for factor in (3.0, 1.5):
        cfg = replace(base, policy_path="artifacts/gm_loco_student_td/policy.onnx", speeds=(1.0,), num_episodes=1,
                      robots_per_batch=1, cell_capacity_factor=factor, record_mcap=False, device="cpu",
                      solver=replace(base.solver, voxel_size=0.06, max_iterations=50, frame_dt=0.01,
                                     rigid_substeps=2))  # fmt: skip
        scene, _, solver = build_cell_scene(episode_specs(cfg), cfg, load_policy(cfg.policy_path, 1))
        for _ in range(8):
            scene.step()
        final[factor] = (np.array(scene.base_q[-1]), solver.max_active_cell_count)
    assert final[1.5][1] < 0.55 * final[3.0][1]
    np.testing.assert_allclose(final[1.5][0], final[3.0][0], atol=1e-6)


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
    spec = EpisodeSpec("dry_sand", "straight", 1.0, 0)
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


def test_an_exit_shortly_before_a_fall_came_with_the_fall() -> None:
    """An early exit 0.3 s before a tilt or a base-height fall is part of the fall.

    One 1 s before, one before a timeout, or none is not.
    """
    row = {"window_exit_early": True, "window_exit_s": 2.7, "alive_s": 3.0, "reason": "tilt", "success": False}
    assert exit_in_fall(row) and exit_in_fall(row | {"reason": "base_height"})
    assert not exit_in_fall(row | {"window_exit_s": 2.0})
    assert not exit_in_fall(row | {"reason": "timeout", "alive_s": 10.0, "window_exit_s": 9.5})
    assert not exit_in_fall(row | {"reason": "success"}) and not exit_in_fall(row | {"window_exit_early": False})
    assert not exit_in_fall({"window_exit_early": True, "reason": "tilt"})  # no times recorded


def test_heading_turn_wraps_around() -> None:
    """A heading going from 170 to -170 degrees turned 20 degrees, not 340; only alive samples count."""
    from gmloco.eval.g1.score import heading_turn_deg

    yaw = np.radians([170.0, 180.0, -170.0, 90.0])
    assert math.isclose(heading_turn_deg(yaw, 3), 20.0, rel_tol=1e-9)
    assert math.isclose(heading_turn_deg(yaw, 4), 80.0, rel_tol=1e-9)


def test_each_group_records_its_best_walk_once_per_cell(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """One recording per group, its best walk, written after the cell.

    Episode 0 falls at step 3, episodes 1-4 stand the 0.2 s out: episode 1 (the first of the longest) is recorded; a
    resumed run replaces it only with a better walk than its sidecar's.
    """
    import gmloco.eval.g1.cell as g1_cell
    import gmloco.eval.g1.record as g1_eval_record
    import gmloco.eval.g1.run as g1_eval

    cfg, _ = _cell(monkeypatch, {0: 3})
    cfg = replace(cfg, record_mcap=True)
    monkeypatch.setattr(g1_eval, "load_policy", lambda path, n=1: _Policy())
    monkeypatch.setattr(g1_cell, "load_policy", lambda path, n=1: _Policy())
    monkeypatch.setattr(g1_eval, "write_outputs", lambda *a, **k: None)
    written: list[str] = []

    def fake_write(path: Path, ep: dict, meta: dict) -> Path:
        written.append(ep["spec"].key)
        Path(path).write_bytes(b"mcap")
        return Path(path)

    monkeypatch.setattr(g1_eval_record, "write_episode_mcap", fake_write)
    g1_eval.run(replace(cfg, out_dir=str(tmp_path)))
    side = tmp_path / "recordings" / "dry_sand__straight__v1.json"
    doc = json.loads(side.read_text())
    assert written == ["dry_sand/straight/1"] and doc["key"] == "dry_sand/straight/1" and not doc["success"]
    assert doc["alive_s"] == pytest.approx(0.2) and (tmp_path / "recordings" / doc["mcap"]).exists()
    g1_eval.run(replace(cfg, out_dir=str(tmp_path), num_episodes=7))  # episodes 5-6 stand 0.2 s: not better
    assert written == ["dry_sand/straight/1"]
    side.write_text(json.dumps(doc | {"alive_s": 0.05}))  # an earlier pick that walked less
    g1_eval.run(replace(cfg, out_dir=str(tmp_path), num_episodes=9))
    # episodes 7-8 in a fresh scene: its lane 0 replays the stand-in's episode-0 fall, so 8 is the better walk
    assert written == ["dry_sand/straight/1", "dry_sand/straight/8"]
    assert g1_eval.recording_rank({"success": True, "alive_s": 8.2}) > g1_eval.recording_rank({"alive_s": 10.0})
