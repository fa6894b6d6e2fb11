# SPDX-License-Identifier: Apache-2.0
"""Data-parallel train(): two CPU ranks (gloo) of the VAE teacher, started by torchrunx, stay in sync."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
import torch

from gmloco.train import TrainRunCfg, g1_granular_task
from gmloco.train.multi_gpu import launch_ranks
from gmloco.train.teacher_student import ObsGroupsCfg, PpoCfg, TeacherCfg

RANKS = 2
"""Worker processes (the test's stand-in for two GPUs)."""


def _teacher_cfg(run_dir: Path) -> TrainRunCfg:
    """A CPU-sized VAE teacher run: 2 envs per rank, 4 steps per env, [32, 32] networks, 4 history frames."""
    teacher = TeacherCfg(
        actor_hidden_dims=(32, 32),
        critic_hidden_dims=(32, 32),
        encoder_hidden_dims=(16, 8),
        decoder_hidden_dims=(8, 16),
        latent_dim=4,
        ppo=PpoCfg(num_learning_epochs=2, num_mini_batches=2, desired_kl=0.001),
    )
    return TrainRunCfg(
        task=replace(g1_granular_task("rft3d"), policy_history_length=1),
        num_envs=2,
        max_iterations=2,
        num_steps_per_env=4,
        device="cpu",
        run_dir=str(run_dir),
        save_interval=1,
        export_onnx=False,
        history_length=4,
        rsl_rl_overrides=teacher.to_rsl_rl(ObsGroupsCfg()),
    )


def _rank_run(args: tuple[TrainRunCfg, str]) -> dict[str, float]:
    """One rank: ``train_rank``, then its actor, critic and learning rate saved to ``<dump>/rank<r>.pt``."""
    import os

    from gmloco.train.rl.runner import GmlocoOnPolicyRunner
    from gmloco.train.training import train_rank

    cfg, dump = args
    learn = GmlocoOnPolicyRunner.learn

    def learn_and_dump(self: GmlocoOnPolicyRunner, *a: object, **k: object) -> None:
        learn(self, *a, **k)  # type: ignore[arg-type]
        state = {"actor": self.alg.actor.state_dict(), "critic": self.alg.critic.state_dict()}
        state["learning_rate"] = self.alg.learning_rate  # type: ignore[assignment]
        torch.save(state, Path(dump) / f"rank{os.environ['RANK']}.pt")

    GmlocoOnPolicyRunner.learn = learn_and_dump  # type: ignore[method-assign]
    return train_rank(cfg)


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_two_cpu_ranks_train_the_teacher_in_sync(tmp_path: Path) -> None:
    """Two gloo ranks train 2 teacher iterations: identical weights and learning rate, rank 0 alone writes files."""
    import sys

    import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])  # the workers cannot import a test module
    run_dir, dump = tmp_path / "run", tmp_path / "dump"
    dump.mkdir()
    metrics = launch_ranks(_rank_run, (_teacher_cfg(run_dir), str(dump)), RANKS, None, str(tmp_path / "torchrunx"))
    assert metrics["iteration"] == 2 and metrics["iterations_done"] == 2
    # env steps count both ranks: 2 ranks x 2 envs x 4 steps x 2 iterations
    assert metrics["env_steps"] == RANKS * 2 * 4 * 2
    ranks = [torch.load(dump / f"rank{r}.pt", weights_only=False) for r in range(RANKS)]
    # the teacher's VAE encoder and eta decoder are part of the actor, so they are broadcast and all-reduced too
    assert {"encoder.mu_head.weight", "decoder.0.weight"} <= set(ranks[0]["actor"])
    for key in ("actor", "critic"):
        params = [dict(r[key]) for r in ranks]
        for name, value in params[0].items():
            if "normalizer" in name:  # running observation statistics stay per rank, as in rsl-rl
                continue
            torch.testing.assert_close(value, params[1][name], rtol=0.0, atol=0.0, msg=f"{key}.{name}")
    # the adaptive rate moved from its initial 1e-3 (KL all-reduced, rate broadcast from rank 0) and agrees
    assert ranks[0]["learning_rate"] == ranks[1]["learning_rate"] != 1.0e-3
    checkpoint = torch.load(run_dir / "model_2.pt", weights_only=False)
    assert checkpoint["learning_rate"] == ranks[0]["learning_rate"]
    # one writer: one checkpoint series, one metrics file, one TensorBoard event file
    assert sorted(p.name for p in run_dir.glob("model_*.pt")) == ["model_1.pt", "model_2.pt"]
    assert len(list(run_dir.glob("events.out.tfevents.*"))) == 1
    assert (run_dir / "metrics.json").exists() and (run_dir / "train_cfg.json").exists()
