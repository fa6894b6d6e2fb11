# SPDX-License-Identifier: Apache-2.0
"""TeacherActor and TeacherPPO: shapes, export wrappers, and a PPO + VAE update on a filled rollout storage."""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace

import numpy as np
import pytest
import torch
from rsl_rl.env import VecEnv
from rsl_rl.models import MLPModel

from gmloco.train.teacher_student import ObsGroupsCfg, PpoSchedule, TeacherActor, TeacherCfg, TeacherPPO
from gmloco.train.teacher_student.teacher_ppo import eta_target


def _build(env: VecEnv, cfg: TeacherCfg, groups: ObsGroupsCfg, complete: Callable[[dict], dict]) -> TeacherPPO:
    """Build TeacherPPO through rsl-rl's own PPO.construct_algorithm."""
    return TeacherPPO.construct_algorithm(env.get_observations(), env, complete(cfg.to_rsl_rl(groups)), "cpu")  # type: ignore[return-value]


def _rollout(alg: TeacherPPO, env: VecEnv, steps: int) -> None:
    """Fill the storage with ``steps`` transitions and compute returns, as rsl-rl's runner does."""
    obs = env.get_observations()
    with torch.inference_mode():
        for _ in range(steps):
            obs, rew, dones, extras = env.step(alg.act(obs))
            alg.process_env_step(obs, rew, dones, extras)
        alg.compute_returns(obs)


def test_teacher_actor_shapes_and_latent_cache(
    toy_env: VecEnv,
    teacher_cfg: TeacherCfg,
    groups: ObsGroupsCfg,
    runner_cfg: Callable[[dict], dict],
    dims: SimpleNamespace,
) -> None:
    """The actor maps the obs to [B, A]; the encoder sees critic + flattened history; mu/logvar are cached."""
    alg = _build(toy_env, teacher_cfg, groups, runner_cfg)
    actor, obs = alg.actor, toy_env.get_observations()
    assert isinstance(actor, TeacherActor) and type(alg.critic) is MLPModel
    assert actor.encoder_obs_dim == (dims.obs_dim + 1) + dims.history * dims.obs_dim  # critic [o_t, eta] + frames
    assert actor.mlp[0].in_features == dims.obs_dim + dims.latent
    assert actor(obs).shape == (dims.num_envs, dims.num_actions)
    assert actor.latent_mu is not None and actor.latent_mu.shape == (dims.num_envs, dims.latent)
    assert actor.decode(actor.latent_mu).shape == (dims.num_envs, 1)
    np.testing.assert_array_equal(eta_target(obs, "critic", -1).numpy(), toy_env.eta.numpy())


def test_teacher_export_wrappers_keep_the_encoder(
    toy_env: VecEnv, teacher_cfg: TeacherCfg, groups: ObsGroupsCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """as_jit / as_onnx take (obs, encoder_obs) and reproduce the deterministic actor exactly."""
    alg = _build(toy_env, teacher_cfg, groups, runner_cfg)
    actor, obs = alg.actor.eval(), toy_env.get_observations()
    expected = actor(obs).detach()
    onnx_like = actor.as_onnx(verbose=False)
    assert onnx_like.input_names == ["obs", "encoder_obs"]
    got = onnx_like(obs["actor"], actor.encoder_input(obs))
    np.testing.assert_allclose(got.detach().numpy(), expected.numpy(), atol=1e-6)
    scripted = torch.jit.script(actor.as_jit())
    np.testing.assert_allclose(
        scripted(obs["actor"], actor.encoder_input(obs)).detach().numpy(), expected.numpy(), atol=1e-6
    )


def test_teacher_ppo_update_trains_encoder_decoder_and_logs_vae_terms(
    toy_env: VecEnv, teacher_cfg: TeacherCfg, groups: ObsGroupsCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """One PPO update on a filled storage runs, logs the VAE terms, and moves encoder and decoder."""
    torch.manual_seed(0)
    alg = _build(toy_env, teacher_cfg, groups, runner_cfg)
    alg.train_mode()
    enc0 = [p.detach().clone() for p in alg.actor.encoder.parameters()]
    dec0 = [p.detach().clone() for p in alg.actor.decoder.parameters()]
    _rollout(alg, toy_env, steps=4)
    logs = alg.update()
    assert {"surrogate", "value", "entropy", "eta_reconstruction", "latent_kl", "eta_r2", "w_ppo"} <= logs.keys()
    assert logs["eta_r2"] <= 1.0
    assert all(np.isfinite(v) for v in logs.values())
    assert any(not torch.equal(a, b) for a, b in zip(enc0, alg.actor.encoder.parameters(), strict=True))
    assert any(not torch.equal(a, b) for a, b in zip(dec0, alg.actor.decoder.parameters(), strict=True))


def test_teacher_vae_loss_decreases_on_a_fixed_batch(
    toy_env: VecEnv, teacher_cfg: TeacherCfg, groups: ObsGroupsCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """Twenty PPO + VAE updates on one stored rollout drive the eta error below the best constant guess.

    eta ~ U[0, 1], so predicting its mean scores Var(eta) = 1/12 ~ 0.083; beating it means z carries eta.
    (Fixed learning rate: with 16-sample mini-batches the adaptive rule would shrink it to 1e-5.)
    """
    torch.manual_seed(0)
    teacher_cfg.kl_weight = 1e-4
    teacher_cfg.ppo.schedule = PpoSchedule.fixed
    alg = _build(toy_env, teacher_cfg, groups, runner_cfg)
    alg.train_mode()
    _rollout(alg, toy_env, steps=4)
    snapshot = {k: (v.clone() if torch.is_tensor(v) else v) for k, v in vars(alg.storage).items()}
    first = alg.update()["eta_reconstruction"]
    for _ in range(20):
        vars(alg.storage).update({k: (v.clone() if torch.is_tensor(v) else v) for k, v in snapshot.items()})
        last = alg.update()["eta_reconstruction"]
    assert last < 0.2 * first
    assert last < 1.0 / 12.0


def test_teacher_ppo_refuses_a_plain_mlp_actor(
    toy_env: VecEnv, groups: ObsGroupsCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """TeacherPPO needs the encoder; a stock MLPModel actor is a clear TypeError."""
    cfg = runner_cfg(TeacherCfg(actor_hidden_dims=(8,), critic_hidden_dims=(8,)).to_rsl_rl(groups))
    cfg["actor"] = {
        "class_name": "MLPModel",
        "hidden_dims": [8],
        "distribution_cfg": {"class_name": "GaussianDistribution"},
    }
    with pytest.raises(TypeError, match="TeacherActor"):
        TeacherPPO.construct_algorithm(toy_env.get_observations(), toy_env, cfg, "cpu")
