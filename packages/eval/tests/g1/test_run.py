# SPDX-License-Identifier: Apache-2.0
"""The run on a stand-in scene: episodes and summary, the episode loop, refill, time box, grid capacity, recordings."""

from __future__ import annotations

import json
import math
import time
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace
from typing import ClassVar

import numpy as np
import pytest

from gmloco.eval.g1.cell import run_cell
from gmloco.eval.g1.config import EpisodeSpec, G1EvalCfg, episode_batches, episode_specs
from gmloco.eval.g1.scene_cfg import LOG_FIELDS
from gmloco.eval.g1.score import score_episode
from gmloco.eval.metrics.episodes import summarize
from gmloco.eval.mpm.box_scene import GridType
from gmloco.eval.report.tables_mpm import table_speeds, table_terrains


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
    # every grid check waits for the frames in flight through the scene's clock first (the scene clock's sync)
    ev = scene.events
    assert ev.count("check") >= 5 and all(ev[i - 1] == "sync" for i, e in enumerate(ev) if e == "check")


def test_idle_lanes_keep_their_sand_when_asked(monkeypatch: pytest.MonkeyPatch) -> None:
    """retire_idle_lanes=False: the same episodes, no lane retired (the runs before ``retire_idle_lanes`` existed)."""
    cfg, specs = _cell(monkeypatch, {0: 3}, retire_idle_lanes=False)
    logs: list[dict] = []
    assert run_cell(specs, cfg, _Policy(), logs.append).finished
    assert [lg["spec"].index for lg in logs] == [0, 1, 2, 3, 4] and _LaneScene.made[0].retired == []


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
        check_grid_capacity(
            _grid_scene(True, calls), MpmSolverCfg(grid_type=GridType.sparse, max_active_cell_count=100)
        )
    assert "100" in str(info.value) and "overflow" in str(info.value)
    assert isinstance(info.value.__cause__, RuntimeError) and calls == [1]


@pytest.mark.parametrize(("grid_type", "capacity"), [(GridType.sparse, -1), (GridType.dense, 100)])
def test_grid_capacity_is_not_checked_without_a_reserved_sparse_grid(grid_type: GridType, capacity: int) -> None:
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
    check_grid_capacity(_grid_scene(False, calls), MpmSolverCfg(grid_type=GridType.sparse, max_active_cell_count=100))
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
