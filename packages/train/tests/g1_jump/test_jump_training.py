# SPDX-License-Identifier: Apache-2.0
"""A tiny CPU PPO run of the jump task: finite losses, checkpoints carrying the assist state, resume."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest
import torch

from gmloco.train import TrainRunCfg, train
from gmloco.train.tasks.g1_jump.config import g1_jump_task


def _cfg(run_dir: Path, **overrides: object) -> TrainRunCfg:
    """2 envs, 8 steps per env, [32, 32] networks, 3D-RFT sand, no export."""
    base = TrainRunCfg(
        jump=g1_jump_task("rft3d"),
        num_envs=2,
        max_iterations=2,
        num_steps_per_env=8,
        hidden_dims=(32, 32),
        device="cpu",
        run_dir=str(run_dir),
        save_interval=1,
        export_onnx=False,
    )
    return replace(base, **overrides)  # type: ignore[arg-type]


def test_jump_run_needs_export_off(tmp_path: Path) -> None:
    """The jump task has no ONNX deploy metadata: asking for export is a clear error before any env is built."""
    with pytest.raises(ValueError, match="export_onnx=False"):
        train(_cfg(tmp_path, export_onnx=True))


def test_ppo_losses_are_finite(tmp_path: Path) -> None:
    """Three PPO updates on the jump env return finite surrogate, value and entropy losses."""
    from gmloco.train.training import _make_env, _make_runner

    cfg = _cfg(tmp_path)
    env = _make_env(cfg)
    try:
        runner = _make_runner(cfg, env, tmp_path)
        losses: list[dict[str, float]] = []
        update = runner.alg.update

        def _record() -> dict[str, float]:
            """Run the PPO update and keep its losses."""
            out = update()
            losses.append(out)
            return out

        runner.alg.update = _record
        runner.learn(3)
    finally:
        env.close()
    assert len(losses) == 3
    for step in losses:
        assert step and all(math.isfinite(float(v)) for v in step.values()), step


def test_two_iterations_then_resume_keep_the_assist_state(tmp_path: Path) -> None:
    """Two iterations write model_2.pt with the assist state; max_iterations=3 resumes for exactly one more."""
    metrics = train(_cfg(tmp_path))
    assert metrics["iteration"] == 2
    # The reward buffer fills only when an episode ends; 2 envs x 16 steps may end none, and then both means are nan.
    assert math.isfinite(metrics["mean_reward"]) == math.isfinite(metrics["mean_episode_length"])
    ckpt = torch.load(tmp_path / "model_2.pt", map_location="cpu", weights_only=False)
    assist = ckpt["infos"]["jump_assist"]
    assert assist["scale"] == pytest.approx(1.0)  # 2 envs x ~16 steps: far from the first judged round
    resumed = train(_cfg(tmp_path, max_iterations=3))
    assert resumed["resumed_from_iteration"] == 2 and resumed["iteration"] == 3


def test_checkpoint_evaluates_in_the_training_simulator(tmp_path: Path) -> None:
    """evaluate_jump_run loads the newest checkpoint of a run and scores one unassisted attempt on rigid ground."""
    from gmloco.train.tasks.g1_jump.evaluation import JumpEvalCfg, evaluate_jump_run

    train(_cfg(tmp_path, max_iterations=1))
    summary, traces = evaluate_jump_run(tmp_path, JumpEvalCfg(contact_model="rigid", attempts=1))
    assert summary["episodes"] == 1.0 and len(traces) == 1 and traces[0].base_pos.shape[0] > 0
    with pytest.raises(ValueError, match="no jump training run"):
        evaluate_jump_run(tmp_path / "missing", JumpEvalCfg(attempts=1))


def test_evaluate_cli_writes_summary_figure_and_manifest(tmp_path: Path) -> None:
    """The CLI scores a run on one material and writes strict-JSON summary.json, the figure and manifest.json."""
    import json

    from gmloco.train.tasks.g1_jump.evaluate import main

    run = tmp_path / "run"
    train(_cfg(run, max_iterations=1))
    out = tmp_path / "results"
    argv = ["--run", f"p={run}", "--materials", "dry_sand", "--attempts", "1", "--out", str(out)]
    assert main(argv) == 0
    scores = json.loads((out / "summary.json").read_text())["p"]["dry_sand"]["training_sim"]
    assert set(scores) == {"success_pct", "height_error_pct", "takeoff_slip_cm", "sinkage_cm", "episodes"}
    assert scores["episodes"] == 1.0
    assert (out / "fig_jump_trace.png").stat().st_size > 10_000
    assert json.loads((out / "manifest.json").read_text())["attempts"] == 1
