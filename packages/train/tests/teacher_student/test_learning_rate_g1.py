# SPDX-License-Identifier: Apache-2.0
"""The teacher's policy KL at a zero step on the real G1 granular env (history group, privileged critic group).

The toy env of ``test_learning_rate.py`` draws fresh tensors each step; the mjlab env keeps circular history
buffers and recomputes its groups in place, so the stored rollout could differ from what the actor saw. Any such
difference shows as a KL above zero before the first optimizer step and pins the KL-adaptive learning rate.
"""

from __future__ import annotations

import contextlib
import io
from collections.abc import Iterator
from dataclasses import replace
from typing import Any

import pytest
import torch

from gmloco.train import g1_granular_task, make_g1_granular_env_cfg
from gmloco.train.teacher_student import ObsGroupsCfg, PpoCfg, TeacherCfg, TeacherPPO

NUM_ENVS = 4
HISTORY = 4
STEPS = 6


@pytest.fixture(scope="module")
def g1_env(device: str) -> Iterator[Any]:
    """A 4-env rft3d G1 env with a 4-frame history group, wrapped for rsl-rl."""
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.rl import RslRlVecEnvWrapper

    cfg = make_g1_granular_env_cfg(g1_granular_task("rft3d"), NUM_ENVS, history_length=HISTORY)
    cfg.seed = 0
    env = RslRlVecEnvWrapper(ManagerBasedRlEnv(cfg=cfg, device=device))
    yield env
    env.close()


def _teacher(env: Any, actor_latent: str) -> TeacherPPO:
    """A [32, 32] teacher with the G1 PPO settings (adaptive schedule, desired KL 0.01, 2 mini-batches)."""
    torch.manual_seed(0)
    cfg = TeacherCfg(
        actor_hidden_dims=(32, 32),
        critic_hidden_dims=(32, 32),
        encoder_hidden_dims=(32, 16),
        decoder_hidden_dims=(16, 32),
        latent_dim=4,
        actor_latent=actor_latent,  # type: ignore[arg-type]
        ppo=replace(PpoCfg(), num_mini_batches=2, num_learning_epochs=1),
    )
    entries = {"num_steps_per_env": STEPS, "save_interval": 1000, "logger": "tensorboard", "multi_gpu": None}
    entries |= cfg.to_rsl_rl(ObsGroupsCfg())
    with contextlib.redirect_stdout(io.StringIO()):
        return TeacherPPO.construct_algorithm(env.get_observations(), env, entries, "cpu")  # type: ignore[return-value]


def _zero_step_kls(env: Any, alg: TeacherPPO) -> list[float]:
    """Roll out with frozen normalizers, then return each mini-batch's KL(stored || recomputed), no step taken."""
    alg.train_mode()
    for norm in (alg.actor.obs_normalizer, alg.actor.encoder_normalizer):
        norm.eval()  # EmpiricalNormalization.update is a no-op outside training mode
    obs = env.get_observations()
    with torch.inference_mode():
        for _ in range(STEPS):
            obs, rew, dones, extras = env.step(alg.act(obs))
            alg.process_env_step(obs, rew, dones, extras)
        alg.compute_returns(obs)
        kls = []
        for batch in alg.storage.mini_batch_generator(alg.num_mini_batches, 1):
            alg.actor(batch.observations, stochastic_output=True)
            old, new = batch.old_distribution_params, alg.actor.output_distribution_params
            kls.append(float(alg.actor.get_kl_divergence(old, new).mean()))  # type: ignore[arg-type]
    alg.storage.clear()
    return kls


def test_g1_teacher_recomputes_the_acting_policy_exactly(g1_env: Any) -> None:
    """Mean latent (the default): every mini-batch's KL before any step is exactly 0 on the real env."""
    assert _zero_step_kls(g1_env, _teacher(g1_env, "mean")) == [0.0, 0.0]


def test_g1_teacher_with_a_sampled_latent_has_kl_at_a_zero_step(g1_env: Any) -> None:
    """A sampled latent in training mode draws new noise in the update: KL > 0 with no step (why "mean" is default)."""
    assert min(_zero_step_kls(g1_env, _teacher(g1_env, "sample"))) > 0.0
