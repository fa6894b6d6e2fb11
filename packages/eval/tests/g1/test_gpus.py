# SPDX-License-Identifier: Apache-2.0
"""One evaluation over several GPUs: cells split into shares, run from the queue, pooled into one run's outputs."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gmloco.eval.g1.cli import _parse, cfg_from_args
from gmloco.eval.g1.config import G1EvalCfg, episode_specs
from gmloco.eval.g1.gpus import CELLS_DIR, run_on_gpus
from gmloco.eval.g1.score import score_episode


def _walk(speed: float, steps: int, fall_at: int | None, dt: float = 0.02) -> dict:
    """A hand-made log: the pelvis walks straight at ``speed``; from ``fall_at`` on it lies at 0.1 m."""
    t = np.arange(1, steps + 1) * dt
    q = np.zeros((steps, 7))
    q[:, 0], q[:, 2], q[:, 6] = speed * t, 0.75, 1.0
    if fall_at is not None:
        q[fall_at:, 2] = 0.1
    qd = np.zeros((steps, 6))
    qd[:, 0] = speed
    weight = np.zeros((steps, 2, 3))
    weight[..., 2] = 0.5 * 30.0 * 9.81
    return {"dt": dt, "base_q": q, "base_qd": qd, "foot_force": weight, "sinkage": np.full(steps, 0.03),
            "foot_sinkage": np.full((steps, 2), 0.03), "start_xy": np.zeros(2), "robot_mass": 30.0,
            "particles": 10, "build_s": 0.1, "sim_s": 1.0, "frames": 4 * steps}  # fmt: skip


def _stand_in(complete_shares: set[int] | None = None):  # noqa: ANN202
    """Launcher writing what a g1_eval_cli share would: its episodes (odd indices fall) and a summary.

    Shares not in ``complete_shares`` (default: all complete) keep only their first episode and say incomplete.
    """
    launched: list[list[str]] = []

    def launch(cmd: list[str], env: dict[str, str], log: Path) -> subprocess.Popen[bytes]:
        launched.append(cmd)
        cfg = cfg_from_args(_parse(cmd[cmd.index("-m") + 2 :]))
        found = Path(cfg.out_dir) / "episodes.jsonl"
        launch.found[Path(cfg.out_dir).name] = found.read_text().count("\n") if found.exists() else 0  # type: ignore[attr-defined]
        specs = episode_specs(cfg)
        done = complete_shares is None or cfg.shard in complete_shares
        rows = [score_episode(s, cfg, _walk(s.speed, 100, 20 if s.index % 2 else None)) for s in specs]
        rows = rows if done else rows[:1]
        out = Path(cfg.out_dir)
        out.mkdir(parents=True, exist_ok=True)
        (out / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
        metrics = {"throughput/episodes_this_call": float(len(rows))}
        (out / "summary.json").write_text(json.dumps({"complete": done, "metrics": metrics}))
        return subprocess.Popen([sys.executable, "-c", "pass"])

    launch.launched = launched  # type: ignore[attr-defined]
    launch.found = {}  # type: ignore[attr-defined]
    return launch


def _cfg(tmp_path: Path) -> G1EvalCfg:
    return replace(G1EvalCfg(), out_dir=str(tmp_path / "run"), terrains=("basalt", "dry_sand"), speeds=(1.0,),
                   num_episodes=6, episode_s=2.0, record_mcap=False)  # fmt: skip


def test_cells_split_over_gpus_pool_into_one_run(tmp_path: Path) -> None:
    """2 cells x 6 episodes on 3 GPUs: 6 shares, every episode once, the pooled run's outputs and metrics."""
    cfg = _cfg(tmp_path)
    launch = _stand_in()
    metrics, complete = run_on_gpus(cfg, ["0", "1", "2"], launch=launch, poll_s=0.01)
    assert complete
    cmds = launch.launched  # type: ignore[attr-defined]
    assert len(cmds) == 6 and all("--shard" in c and "--device" not in c for c in cmds)
    run = Path(cfg.out_dir)
    rows = [json.loads(line) for line in (run / "episodes.jsonl").read_text().splitlines()]
    assert sorted(r["key"] for r in rows) == sorted(s.key for s in episode_specs(cfg))
    assert metrics["basalt/straight/num_episodes"] == 6.0 and metrics["all/success_rate"] == pytest.approx(0.5)
    assert metrics["throughput/episodes_this_call"] == 12.0 and metrics["throughput/gpus"] == 3.0
    summary = json.loads((run / "summary.json").read_text())
    assert summary["complete"] and (run / "table_terrains.md").exists()
    queue = json.loads((run / CELLS_DIR / "queue.json").read_text())
    assert set(queue["rows"]) == {"basalt__straight", "dry_sand__straight"}


def test_an_unfinished_share_leaves_the_run_incomplete(tmp_path: Path) -> None:
    """Share 1 of 2 stops after one episode: the run is incomplete and pools what the shares finished."""
    cfg = _cfg(tmp_path)
    metrics, complete = run_on_gpus(cfg, ["0", "1"], launch=_stand_in({0}), poll_s=0.01)
    assert not complete and metrics["all/num_episodes"] == 3 + 1 + 3 + 1
    assert not json.loads((Path(cfg.out_dir) / "summary.json").read_text())["complete"]


def test_a_sharded_config_is_refused(tmp_path: Path) -> None:
    """A config that is already one share cannot be split again."""
    with pytest.raises(ValueError, match="shards the cells itself"):
        run_on_gpus(replace(_cfg(tmp_path), shards=2), ["0", "1"], launch=_stand_in())


def test_shares_start_from_a_pooled_file(tmp_path: Path) -> None:
    """A run folder whose episodes.jsonl another run wrote (3 basalt episodes): each share starts from its part."""
    cfg = _cfg(tmp_path)
    run = Path(cfg.out_dir)
    run.mkdir(parents=True)
    earlier = [score_episode(s, cfg, _walk(1.0, 100, None)) for s in episode_specs(cfg)[:3]]  # basalt 0, 1, 2
    (run / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in earlier))
    launch = _stand_in()
    run_on_gpus(cfg, ["0", "1"], launch=launch, poll_s=0.01)
    found = launch.found  # type: ignore[attr-defined]
    assert found["basalt__straight__share0of2"] == 2 and found["basalt__straight__share1of2"] == 1
    assert found["dry_sand__straight__share0of2"] == 0


def test_a_failed_share_is_an_error_that_keeps_the_others(tmp_path: Path) -> None:
    """A share whose process exits 3: RuntimeError naming it and its log, the other shares' episodes pooled."""
    cfg = replace(_cfg(tmp_path), terrains=("basalt",))
    inner = _stand_in()

    def launch(cmd: list[str], env: dict[str, str], log: Path) -> subprocess.Popen[bytes]:
        if cmd[cmd.index("--out") + 1].endswith("share1of2"):
            return subprocess.Popen([sys.executable, "-c", "raise SystemExit(3)"])
        return inner(cmd, env, log)

    with pytest.raises(RuntimeError, match=r"1 of 2 shares failed: basalt__straight__share1of2 exited with 3 \(log"):
        run_on_gpus(cfg, ["0", "1"], launch=launch, poll_s=0.01)
    rows = (Path(cfg.out_dir) / "episodes.jsonl").read_text().splitlines()
    assert len(rows) == 3  # share 0's episodes 0, 2, 4
