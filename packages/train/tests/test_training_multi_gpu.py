# SPDX-License-Identifier: Apache-2.0
"""Data-parallel train(): two CPU ranks (gloo), started by torchrunx, train the teacher and the student in sync.

Each launch builds the G1 env in two fresh processes (about a minute each on two CPU cores), hence ``slow``.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
import torch

from gmloco.train import TrainRunCfg, g1_granular_task
from gmloco.train.multi_gpu import launch_ranks
from gmloco.train.teacher_student import DistillCfg, ObsGroupsCfg, PpoCfg, StudentCfg, TeacherCfg

pytestmark = [pytest.mark.slow, pytest.mark.timeout(900)]

RANKS = 2
"""Worker processes (the test's stand-in for two GPUs)."""
HISTORY = 8
"""Frames of the ``history`` group (teacher encoder and student TCN: 8 -> 4 -> 3 -> 2)."""
TEACHER = TeacherCfg(
    actor_hidden_dims=(32, 32),
    critic_hidden_dims=(32, 32),
    encoder_hidden_dims=(16, 8),
    decoder_hidden_dims=(8, 16),
    latent_dim=4,
    ppo=PpoCfg(num_learning_epochs=2, num_mini_batches=2, desired_kl=0.001),
)
"""A [32, 32] VAE teacher whose adaptive learning rate moves within two iterations."""


def _run_cfg(run_dir: Path, overrides: dict[str, Any], **fields: Any) -> TrainRunCfg:
    """A CPU-sized run: 2 envs per rank, 4 steps per env, 2 iterations, one actor frame, no export."""
    task = replace(g1_granular_task("rft3d"), policy_history_length=1)
    base = TrainRunCfg(task=task, num_envs=2, max_iterations=2, num_steps_per_env=4, device="cpu", save_interval=1)
    return replace(
        base, run_dir=str(run_dir), export_onnx=False, history_length=HISTORY, rsl_rl_overrides=overrides, **fields
    )


def _student_overrides() -> dict[str, Any]:
    """The student's rsl-rl entries (as ``workflows.policy_training.distill_overrides`` builds them)."""
    student = StudentCfg(
        actor_hidden_dims=(32, 32),
        history_length=HISTORY,
        tcn_channels=(8, 8, 8),
        tcn_kernel_sizes=(2, 2, 2),
        tcn_strides=(2, 1, 1),
        tcn_mlp_hidden_dims=(16,),
    )
    ppo = PpoCfg(num_learning_epochs=2, num_mini_batches=2, schedule="fixed")
    entries = DistillCfg(w_ppo_start=0.5, ppo=ppo).to_rsl_rl(TEACHER, student, ObsGroupsCfg())
    for key in ("class_name", "teacher_checkpoint"):
        entries.pop(key)
    return entries


def _rank_run(args: tuple[TrainRunCfg, str]) -> dict[str, float]:
    """One rank: ``train_rank``, then its models and learning rate saved to ``<dump>/rank<r>.pt``."""
    import os

    from gmloco.train.rl.runner import GmlocoOnPolicyRunner
    from gmloco.train.training import train_rank

    cfg, dump = args
    learn = GmlocoOnPolicyRunner.learn

    def learn_and_dump(self: GmlocoOnPolicyRunner, *a: Any, **k: Any) -> None:
        learn(self, *a, **k)
        alg: Any = self.alg
        state = {"actor": alg.actor.state_dict(), "critic": alg.critic.state_dict(), "lr": alg.learning_rate}
        if hasattr(alg, "teacher"):
            state["teacher"] = alg.teacher.state_dict()
        torch.save(state, Path(dump) / f"rank{os.environ['RANK']}.pt")

    GmlocoOnPolicyRunner.learn = learn_and_dump  # type: ignore[method-assign]
    return train_rank(cfg)


def _launch(cfg: TrainRunCfg, dump: Path) -> tuple[dict[str, float], list[dict[str, Any]]]:
    """Run ``cfg`` on :data:`RANKS` CPU ranks; return rank 0's metrics and every rank's dumped state."""
    import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])  # the workers cannot import a test module
    dump.mkdir(parents=True)
    metrics = launch_ranks(_rank_run, (cfg, str(dump)), RANKS, None, str(dump / "torchrunx"))
    return metrics, [torch.load(dump / f"rank{r}.pt", weights_only=False) for r in range(RANKS)]


def _assert_same_weights(ranks: list[dict[str, Any]], keys: tuple[str, ...]) -> None:
    """Every parameter of ``keys`` is bit-identical on all ranks (running observation statistics excepted)."""
    for key in keys:
        for name, value in ranks[0][key].items():
            if "normalizer" in name:  # each rank keeps its own running statistics, as in rsl-rl
                continue
            for other in ranks[1:]:
                torch.testing.assert_close(value, other[key][name], rtol=0.0, atol=0.0, msg=f"{key}.{name}")


@pytest.fixture(scope="module")
def teacher_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, float], list[dict[str, Any]]]:
    """Two ranks train the VAE teacher for two iterations: (run directory, metrics, each rank's state)."""
    root = tmp_path_factory.mktemp("teacher")
    metrics, ranks = _launch(_run_cfg(root / "run", TEACHER.to_rsl_rl(ObsGroupsCfg())), root / "dump")
    return root / "run", metrics, ranks


def test_two_ranks_train_the_teacher_in_sync(teacher_run: tuple[Path, dict[str, float], list[dict]]) -> None:
    """Identical weights (VAE encoder and decoder included) and learning rate; rank 0 alone writes files."""
    run_dir, metrics, ranks = teacher_run
    assert metrics["iteration"] == 2 and metrics["iterations_done"] == 2
    assert metrics["env_steps"] == RANKS * 2 * 4 * 2  # ranks x envs x steps x iterations
    assert {"encoder.mu_head.weight", "decoder.0.weight"} <= set(ranks[0]["actor"])
    _assert_same_weights(ranks, ("actor", "critic"))
    # the adaptive rate moved from its initial 1e-3 (KL all-reduced, rate broadcast from rank 0) and agrees
    assert ranks[0]["lr"] == ranks[1]["lr"] != 1.0e-3
    assert torch.load(run_dir / "model_2.pt", weights_only=False)["learning_rate"] == ranks[0]["lr"]
    # one writer: one checkpoint series, one TensorBoard event file, one metrics file
    assert sorted(p.name for p in run_dir.glob("model_*.pt")) == ["model_1.pt", "model_2.pt"]
    assert len(list(run_dir.glob("events.out.tfevents.*"))) == 1
    assert (run_dir / "metrics.json").exists() and (run_dir / "train_cfg.json").exists()


def test_two_ranks_distill_the_student_in_sync(
    teacher_run: tuple[Path, dict[str, float], list[dict]], tmp_path: Path
) -> None:
    """StudentPPO (DAgger + PPO) from the teacher checkpoint: same student and critic, same frozen teacher."""
    teacher_dir, _, _ = teacher_run
    cfg = _run_cfg(tmp_path / "run", _student_overrides(), init_checkpoint=str(teacher_dir / "model_2.pt"))
    metrics, ranks = _launch(cfg, tmp_path / "dump")
    assert metrics["iteration"] == 2
    assert any(name.startswith("encoder") for name in ranks[0]["actor"])  # the student's TCN
    _assert_same_weights(ranks, ("actor", "critic", "teacher"))
    saved = torch.load(teacher_dir / "model_2.pt", weights_only=False)["actor_state_dict"]
    assert all(torch.equal(saved[k], v) for k, v in ranks[1]["teacher"].items())
    assert sorted(p.name for p in (tmp_path / "run").glob("model_*.pt")) == ["model_1.pt", "model_2.pt"]


def test_two_ranks_resume_the_teacher(teacher_run: tuple[Path, dict[str, float], list[dict]]) -> None:
    """The same call with one more iteration resumes both ranks from rank 0's newest checkpoint."""
    run_dir, _, _ = teacher_run
    cfg = _run_cfg(run_dir, TEACHER.to_rsl_rl(ObsGroupsCfg()), max_iterations=3)
    metrics, ranks = _launch(cfg, run_dir.parent / "dump_resumed")
    assert metrics["resumed_from_iteration"] == 2 and metrics["iterations_done"] == 1 and metrics["iteration"] == 3
    _assert_same_weights(ranks, ("actor", "critic"))
    assert (run_dir / "model_3.pt").exists()
