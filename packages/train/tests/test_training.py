# SPDX-License-Identifier: Apache-2.0
"""train(): two-iteration smoke run, resume from the last checkpoint, time box, ONNX export and evaluation."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gmloco.train import EvalCfg, TrainRunCfg, evaluate_policy, g1_granular_task, train


def _cfg(run_dir: Path, **overrides: object) -> TrainRunCfg:
    """A CPU-sized run: 2 envs, 4 steps per env, [32, 32] networks."""
    base = TrainRunCfg(
        task=g1_granular_task("rft3d"),
        num_envs=2,
        max_iterations=2,
        num_steps_per_env=4,
        hidden_dims=(32, 32),
        device="cpu",
        run_dir=str(run_dir),
        save_interval=1,
    )
    return replace(base, **overrides)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Directory of the module's training run (shared by the smoke, resume and eval tests, in order)."""
    return tmp_path_factory.mktemp("ppo_rft3d")


def test_two_iteration_smoke_run(run_dir: Path) -> None:
    """Two PPO iterations on the 3D-RFT task write checkpoints, TensorBoard events, metrics and policy.onnx."""
    metrics = train(_cfg(run_dir))
    assert metrics["iterations_done"] == 2 and metrics["iteration"] == 2
    assert metrics["env_steps"] == 2 * 4 * 2
    assert metrics["env_steps_per_second"] > 0 and metrics["seconds_per_iteration"] > 0
    for key in ("mean_reward", "mean_episode_length", "collection_seconds_per_iteration", "wall_seconds"):
        assert key in metrics
    assert (run_dir / "model_2.pt").exists() and not list(run_dir.glob("*.tmp"))
    assert list(run_dir.glob("events.out.tfevents.*"))
    assert json.loads((run_dir / "metrics.json").read_text())["iteration"] == 2


def test_resume_continues_from_last_checkpoint(run_dir: Path) -> None:
    """The same config with max_iterations=3 loads model_2.pt and runs exactly one more iteration."""
    metrics = train(_cfg(run_dir, max_iterations=3))
    assert metrics["resumed_from_iteration"] == 2
    assert metrics["iterations_done"] == 1 and metrics["iteration"] == 3
    assert (run_dir / "model_3.pt").exists()


def test_checkpoint_carries_the_curriculum_step_counter(run_dir: Path) -> None:
    """The env's ``common_step_counter`` (command stages, reward ramps) is saved: resumed chunks continue them."""
    import torch

    ckpt = torch.load(run_dir / "model_3.pt", map_location="cpu", weights_only=False)
    assert ckpt["infos"]["env_state"]["common_step_counter"] == 3 * 4


def test_resume_from_a_slim_checkpoint(run_dir: Path, tmp_path: Path) -> None:
    """A checkpoint without optimizer state (the committed artifacts) resumes with its weights and iteration."""
    import shutil

    import torch

    slim_dir = tmp_path / "slim"
    shutil.copytree(run_dir, slim_dir)
    ckpt = torch.load(slim_dir / "model_3.pt", map_location="cpu", weights_only=False)
    ckpt.pop("optimizer_state_dict")
    torch.save(ckpt, slim_dir / "model_3.pt")
    metrics = train(_cfg(slim_dir, max_iterations=4))
    assert metrics["resumed_from_iteration"] == 3 and metrics["iteration"] == 4


def test_resume_refuses_a_changed_task(run_dir: Path) -> None:
    """Resuming a run directory with another contact model is an error, not a silent mix."""
    with pytest.raises(ValueError, match="task"):
        train(_cfg(run_dir, task=g1_granular_task("rigid"), max_iterations=4))


def test_policy_onnx_carries_deploy_metadata(run_dir: Path) -> None:
    """policy.onnx metadata: joint order, kp/kd, default pose, action scale 0.25, actor layout, contact model."""
    import onnx

    meta = {p.key: p.value for p in onnx.load(str(run_dir / "policy.onnx")).metadata_props}
    joints = meta["joint_names"].split(",")
    assert len(joints) == 29 and meta["action_joint_names"].split(",") == joints
    assert len(meta["joint_stiffness"].split(",")) == 29 and len(meta["default_joint_pos"].split(",")) == 29
    assert float(meta["action_scale"]) == pytest.approx(0.25)
    assert meta["contact_model"] == "rft3d" and meta["observation_history_length"] == "5"
    assert [float(d) for d in meta["observation_dims"].split(",")] == [3, 3, 3, 29, 29, 29]  # mjlab writes "%.3f"


def test_policy_onnx_runs_from_its_gmloco_metadata(run_dir: Path) -> None:
    """The versioned document: stacked layout, 5 frames oldest first, collider, dt, effort; the runner steps it."""
    import numpy as np

    from gmloco.deploy.export import OnnxPolicyRunner, read_policy_metadata

    meta = read_policy_metadata(run_dir / "policy.onnx")
    obs = meta.observation
    assert obs.layout == "term_stacked" and obs.history_length == 5 and obs.history_order == "oldest_first"
    assert [t.dim for t in obs.terms] == [3, 3, 3, 29, 29, 29]
    assert meta.timing.physics_dt == pytest.approx(0.005) and meta.timing.decimation == 4
    assert meta.contact.model == "rft3d" and meta.contact.foot_collider.faces == "sole"
    assert meta.contact.foot_collider.body_names == ["left_ankle_roll_link", "right_ankle_roll_link"]
    assert meta.joints.effort_limit[meta.joints.names.index("left_knee_joint")] == pytest.approx(139.0)
    assert json.loads((run_dir / "policy.json").read_text()) == meta.to_dict()
    runner = OnnxPolicyRunner(run_dir / "policy.onnx", num_envs=2)
    zeros = {t.name: np.zeros((2, t.dim), dtype=np.float32) for t in obs.terms}
    heading = np.zeros(2) if meta.command.yaw_command == "yaw_target" else None
    actions = runner.step(zeros, heading=heading)
    assert actions.shape == (2, 29) and np.isfinite(actions).all()


def test_evaluate_exported_policy(run_dir: Path) -> None:
    """evaluate_policy rolls the ONNX policy out per (material, speed) and reports bounded metrics."""
    metrics = evaluate_policy(
        EvalCfg(
            policy_path=str(run_dir / "policy.onnx"), materials=("dry_sand",), speeds=(1.0,), repeats=1, duration_s=0.2
        )
    )
    assert metrics["dry_sand/v1/num_envs"] == 1
    assert 0.0 <= metrics["all/success_rate"] <= 1.0
    assert np.isfinite(metrics["dry_sand/v1/vel_error"]) and metrics["dry_sand/v1/vel_error"] >= 0.0


def test_time_box_stops_early(tmp_path: Path) -> None:
    """A budget smaller than two iterations stops after one, saves it and says so."""
    metrics = train(_cfg(tmp_path, max_iterations=50, max_minutes=0.001, export_reserve_s=0.0, export_onnx=False))
    assert metrics["stopped_by_deadline"] == 1.0 and metrics["iterations_done"] == 1
    assert (tmp_path / "model_1.pt").exists()
