# SPDX-License-Identifier: Apache-2.0
"""Contract tests of the teacher's KL-adaptive learning rate on a short CPU run (toy terrain env).

The committed teachers trained with the rate at the schedule's 1e-5 floor for every logged iteration: the encoder
sat in a fixed-rate group at 1e-3 while its latent feeds the actor, so it alone moved the policy 40-70x past the KL
target (measured on the G1 teacher: mean KL 0.4-0.7 per update at an actor rate of 1e-5, 0.015-0.019 with the
encoder under the adaptive rate). These tests fail on that design.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import pytest
import torch
from rsl_rl.env import VecEnv

from gmloco.train.teacher_student import ObsGroupsCfg, PpoCfg, PpoSchedule, TeacherCfg, TeacherPPO

ITERATIONS = 40
DESIRED_KL = 0.01
"""Target KL of the adaptive schedule in these tests [nats] (the G1 teacher's)."""


def _rollout(env: VecEnv, alg: TeacherPPO, obs: object, steps: int = 4) -> object:
    """Fill the rollout storage as rsl-rl's runner does (normalizers update after every step); return the obs."""
    with torch.inference_mode():
        for _ in range(steps):
            obs, rew, dones, extras = env.step(alg.act(obs))  # type: ignore[arg-type]
            alg.process_env_step(obs, rew, dones, extras)  # type: ignore[arg-type]
        alg.compute_returns(obs)  # type: ignore[arg-type]
    return obs


def _minibatch_kls(alg: TeacherPPO) -> list[float]:
    """Mean KL(stored || recomputed) of every mini-batch of one epoch, with no optimizer step in between."""
    kls = []
    for batch in alg.storage.mini_batch_generator(alg.num_mini_batches, 1):
        with torch.inference_mode():
            alg.actor(batch.observations, stochastic_output=True)
            old, new = batch.old_distribution_params, alg.actor.output_distribution_params
            kls.append(float(alg.actor.get_kl_divergence(old, new).mean()))  # type: ignore[arg-type]
    return kls


def _train(env: VecEnv, alg: TeacherPPO, iterations: int) -> dict[str, list[float]]:
    """Run ``iterations`` rollouts + updates as rsl-rl's runner does; return the lr, std and mean KL per update."""
    log: dict[str, list[float]] = {"lr": [], "std": [], "kl": []}
    kls: list[float] = []
    adapt = alg._adapt_learning_rate

    def spy(batch: object) -> None:
        with torch.inference_mode():
            old, new = batch.old_distribution_params, alg.actor.output_distribution_params  # type: ignore[attr-defined]
            kls.append(float(alg.actor.get_kl_divergence(old, new).mean()))
        adapt(batch)  # type: ignore[arg-type]

    alg._adapt_learning_rate = spy  # type: ignore[method-assign]
    alg.train_mode()
    obs = env.get_observations()
    for _ in range(iterations):
        obs = _rollout(env, alg, obs)
        kls.clear()
        alg.update()
        log["lr"].append(alg.learning_rate)
        log["std"].append(float(alg.actor.output_std.detach().mean()))
        log["kl"].append(sum(kls) / len(kls))
    return log


def _teacher(
    make_env: Callable[..., VecEnv], cfg: TeacherCfg, runner_cfg: Callable[[dict], dict]
) -> tuple[VecEnv, TeacherPPO]:
    """A 256-env toy env and a teacher with the adaptive schedule (desired KL 0.01, start 1e-3)."""
    torch.manual_seed(0)
    env = make_env(num_envs=256, seed=0)
    ppo = replace(
        cfg.ppo, schedule=PpoSchedule.adaptive, desired_kl=DESIRED_KL, learning_rate=1e-3, num_learning_epochs=5
    )
    teacher = replace(cfg, ppo=ppo, init_std=1.0)
    alg = TeacherPPO.construct_algorithm(
        env.get_observations(), env, runner_cfg(teacher.to_rsl_rl(ObsGroupsCfg())), "cpu"
    )
    return env, alg  # type: ignore[return-value]


@pytest.mark.parametrize("entropy_coef", [0.0, PpoCfg().entropy_coef])
def test_adaptive_rate_moves_both_ways_and_the_actor_learns(
    make_env: Callable[..., VecEnv], teacher_cfg: TeacherCfg, runner_cfg: Callable[[dict], dict], entropy_coef: float
) -> None:
    """On a short run the adaptive rate rises and falls, reaches above 3e-4, the actor moves and its std falls.

    Run with no entropy bonus and with the package default (0.005): the bonus must not hold the std up.
    """
    cfg = replace(teacher_cfg, ppo=replace(teacher_cfg.ppo, entropy_coef=entropy_coef))
    env, alg = _teacher(make_env, cfg, runner_cfg)
    mlp0 = [p.detach().clone() for p in alg.actor.mlp.parameters()]
    log = _train(env, alg, ITERATIONS)
    steps = [b / a for a, b in zip(log["lr"], log["lr"][1:], strict=False)]
    assert any(s > 1.0 for s in steps) and any(s < 1.0 for s in steps), log["lr"]
    assert max(log["lr"]) > 3e-4, log["lr"]  # the committed G1 teachers never logged a rate above 3e-4
    assert min(log["lr"][ITERATIONS // 2 :]) > 1e-5, log["lr"]  # never pinned at the floor once settled
    assert sum(log["kl"][-10:]) / 10 < 4 * DESIRED_KL, log["kl"]  # the KL is held near its target
    assert log["std"][-1] < 0.8 * log["std"][0], log["std"]
    moved = [float((p - q).abs().max()) for p, q in zip(alg.actor.mlp.parameters(), mlp0, strict=True)]
    assert max(moved) > 1e-2, moved


def test_first_minibatch_kl_is_zero_before_any_step(
    make_env: Callable[..., VecEnv], teacher_cfg: TeacherCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """Recomputed on the stored observations before any step, the policy equals the one that acted.

    A KL above zero at a zero step (a sampled latent in the update, an encoder that differs between rollout and
    update, a stored observation that the env overwrote) pins the adaptive rate whatever the step size. Only the
    running normalizers move between acting and updating; after two warm-up rollouts (3,072 samples in their
    statistics) 1,024 more shift them by ~1e-5 nats of KL, so the bound is desired_kl / 100.
    """
    env, alg = _teacher(make_env, teacher_cfg, runner_cfg)
    alg.train_mode()
    obs = env.get_observations()
    for _ in range(2):
        obs = _rollout(env, alg, obs)
        alg.update()
    _rollout(env, alg, obs)
    kls = _minibatch_kls(alg)
    assert len(kls) == alg.num_mini_batches
    assert max(kls) < DESIRED_KL / 100, kls


def test_frozen_normalizers_give_an_exact_zero_kl(
    make_env: Callable[..., VecEnv], teacher_cfg: TeacherCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """With the running statistics frozen (eval-mode normalizers) the recomputed distribution is bit-identical."""
    env, alg = _teacher(make_env, teacher_cfg, runner_cfg)
    alg.train_mode()
    for norm in (alg.actor.obs_normalizer, alg.actor.encoder_normalizer):
        norm.eval()  # EmpiricalNormalization.update is a no-op outside training mode
    _rollout(env, alg, env.get_observations())
    assert _minibatch_kls(alg) == [0.0] * alg.num_mini_batches


def test_encoder_follows_the_adaptive_rate_and_decoder_keeps_its_own(
    make_env: Callable[..., VecEnv], teacher_cfg: TeacherCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """The encoder (on the action path) is in the policy's group; only the decoder has the fixed rate."""
    env, alg = _teacher(make_env, replace(teacher_cfg, decoder_learning_rate=3e-3), runner_cfg)
    policy_group, decoder_group = alg.optimizer.param_groups
    encoder = {id(p) for p in alg.actor.encoder.parameters()}
    assert encoder <= {id(p) for p in policy_group["params"]}
    assert {id(p) for p in decoder_group["params"]} == {id(p) for p in alg.actor.decoder.parameters()}
    _train(env, alg, 3)
    assert decoder_group["lr"] == 3e-3 and policy_group["lr"] == alg.learning_rate


def test_learning_rate_survives_a_checkpoint(
    make_env: Callable[..., VecEnv], teacher_cfg: TeacherCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """A resumed run starts from the saved adaptive rate, not from the schedule's initial 1e-3."""
    env, alg = _teacher(make_env, teacher_cfg, runner_cfg)
    _train(env, alg, 5)
    alg.learning_rate = 2.5e-4
    saved = alg.save()
    _, fresh = _teacher(make_env, teacher_cfg, runner_cfg)
    fresh.load(saved, None, strict=True)
    assert fresh.learning_rate == 2.5e-4
    assert all(g["lr"] == 2.5e-4 for g in fresh.optimizer.param_groups if not g.get("fixed_lr", False))
    saved.pop("optimizer_state_dict")  # a slim checkpoint: fresh Adam, same rate
    _, slim = _teacher(make_env, teacher_cfg, runner_cfg)
    slim.load(saved, None, strict=True)
    assert slim.learning_rate == 2.5e-4


def test_only_the_adaptive_rate_moves_the_actions(
    make_env: Callable[..., VecEnv], teacher_cfg: TeacherCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """With the policy's rate at 0 an update leaves every action unchanged.

    Nothing outside the KL-controlled group (here the decoder, still training at its own rate) is on the action
    path. The rollout is collected first, so the observation normalizers' update is not part of the comparison.
    """
    torch.manual_seed(0)
    env = make_env(num_envs=64, seed=0)
    ppo = replace(teacher_cfg.ppo, schedule=PpoSchedule.fixed, learning_rate=0.0)
    cfg = runner_cfg(replace(teacher_cfg, ppo=ppo, decoder_learning_rate=1e-2).to_rsl_rl(ObsGroupsCfg()))
    alg: TeacherPPO = TeacherPPO.construct_algorithm(env.get_observations(), env, cfg, "cpu")  # type: ignore[assignment]
    probe = env.get_observations().clone()
    decoder0 = [p.detach().clone() for p in alg.actor.decoder.parameters()]
    alg.train_mode()
    obs = env.get_observations()
    with torch.inference_mode():
        for _ in range(4):
            obs, rew, dones, extras = env.step(alg.act(obs))
            alg.process_env_step(obs, rew, dones, extras)
        alg.compute_returns(obs)
    alg.actor.eval()
    before = alg.actor(probe).detach()
    alg.actor.train()
    alg.update()
    alg.actor.eval()
    torch.testing.assert_close(alg.actor(probe).detach(), before)
    assert any(not torch.equal(a, b) for a, b in zip(decoder0, alg.actor.decoder.parameters(), strict=True))
