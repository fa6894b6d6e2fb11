# SPDX-License-Identifier: Apache-2.0
"""StudentActor and StudentPPO (DAgger + PPO): frozen teacher, loss decrease, teacher loading, checkpoints."""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace

import numpy as np
import torch
from rsl_rl.env import VecEnv

from gmloco.train.teacher_student import (
    LinearRamp,
    StudentActor,
    StudentPPO,
)


def _rollout(alg: StudentPPO, env: VecEnv, steps: int) -> torch.Tensor:
    """Collect ``steps`` transitions; return the actions the env received, ``[steps, num_envs, A]``."""
    obs, sent = env.get_observations(), []
    with torch.inference_mode():
        for _ in range(steps):
            actions = alg.act(obs)
            sent.append(actions.clone())
            obs, rew, dones, extras = env.step(actions)
            alg.process_env_step(obs, rew, dones, extras)
        alg.compute_returns(obs)
    return torch.stack(sent)


def _snapshot(alg: StudentPPO) -> dict:
    """Copy the storage state so the same batch can be replayed."""
    return {k: (v.clone() if torch.is_tensor(v) else v) for k, v in vars(alg.storage).items()}


def test_student_actor_shapes_and_jit_export(student_alg: StudentPPO, toy_env: VecEnv, dims: SimpleNamespace) -> None:
    """The student maps obs to [B, A], caches z_hat [B, Z], and its TorchScript export keeps the encoder."""
    actor, obs = student_alg.actor.eval(), toy_env.get_observations()
    assert isinstance(actor, StudentActor)
    assert actor(obs).shape == (dims.num_envs, dims.num_actions)
    assert actor.latent is not None and actor.latent.shape == (dims.num_envs, dims.latent)
    assert sum(isinstance(m, torch.nn.Conv1d) for m in actor.encoder.modules()) == 3
    scripted = torch.jit.script(actor.as_jit())
    np.testing.assert_allclose(
        scripted(obs["actor"], obs["history"]).detach().numpy(), actor(obs).detach().numpy(), atol=1e-6
    )


def test_loading_the_teacher_initialises_the_student(student_alg: StudentPPO, teacher_ckpt: dict) -> None:
    """Teacher weights load; psi, the actor MLP, the o_t normalizer and the critic are copied into the student."""
    assert student_alg.teacher_loaded
    for key, value in teacher_ckpt["actor_state_dict"].items():
        assert torch.equal(student_alg.teacher.state_dict()[key], value)
    for name in ("decoder", "mlp", "obs_normalizer"):
        a, b = getattr(student_alg.actor, name).state_dict(), getattr(student_alg.teacher, name).state_dict()
        assert all(torch.equal(a[k], b[k]) for k in a)
    for key, value in teacher_ckpt["critic_state_dict"].items():
        assert torch.equal(student_alg.critic.state_dict()[key], value)


def test_teacher_stays_frozen_during_distillation(student_alg: StudentPPO, toy_env: VecEnv) -> None:
    """After rollouts and updates the teacher is bit-identical, has requires_grad False and stays in eval mode."""
    before = {k: v.clone() for k, v in student_alg.teacher.state_dict().items()}
    decoder_before = {k: v.clone() for k, v in student_alg.actor.decoder.state_dict().items()}
    student_alg.train_mode()
    for _ in range(2):
        _rollout(student_alg, toy_env, steps=4)
        student_alg.update()
    after = student_alg.teacher.state_dict()
    assert all(torch.equal(before[k], after[k]) for k in before)  # normalizer buffers included
    assert all(not p.requires_grad for p in student_alg.teacher.parameters())
    assert not student_alg.teacher.training
    assert all(torch.equal(decoder_before[k], v) for k, v in student_alg.actor.decoder.state_dict().items())
    optimized = {id(p) for group in student_alg.optimizer.param_groups for p in group["params"]}
    assert not optimized & {id(p) for p in student_alg.teacher.parameters()}


def test_dagger_the_env_receives_student_actions(student_alg: StudentPPO, toy_env: VecEnv) -> None:
    """DAgger: the stored (and executed) actions are the student's samples, not the teacher's labels."""
    sent = _rollout(student_alg, toy_env, steps=2)
    np.testing.assert_array_equal(student_alg.storage.actions[:2].numpy(), sent.numpy())


def test_distillation_steps_reduce_action_and_latent_losses(student_alg: StudentPPO, toy_env: VecEnv) -> None:
    """A few DAgger updates on one fixed batch lower ||a - a_hat||^2 and ||z - z_hat||^2."""
    student_alg.train_mode()
    _rollout(student_alg, toy_env, steps=4)
    batch = _snapshot(student_alg)
    first = student_alg.update()
    for _ in range(10):
        vars(student_alg.storage).update(_snapshot_copy(batch))
        last = student_alg.update()
    assert last["distill_action"] < 0.5 * first["distill_action"] or last["distill_action"] < 1e-4
    assert last["distill_latent"] < 0.5 * first["distill_latent"]
    assert last["distill_decoded"] < first["distill_decoded"]
    assert last["w_ppo"] == 0.0 and last["w_dist"] == 1.0
    assert np.isfinite(last["eta_r2"]) and last["eta_r2"] <= 1.0  # logged next to eta_error


def _snapshot_copy(batch: dict) -> dict:
    """Return a fresh copy of a storage snapshot."""
    return {k: (v.clone() if torch.is_tensor(v) else v) for k, v in batch.items()}


def test_student_checkpoint_round_trip_keeps_curriculum_and_teacher(
    student_alg: StudentPPO, toy_env: VecEnv, new_student: Callable[[int], StudentPPO]
) -> None:
    """save() then load() into a fresh StudentPPO restores student, teacher and the curriculum position."""
    student_alg.train_mode()
    _rollout(student_alg, toy_env, steps=4)
    student_alg.update()
    saved = student_alg.save()
    assert saved["distill_updates"] == 1 and "teacher_state_dict" in saved
    fresh = new_student(1)
    assert fresh.load(saved, None, strict=True) is True
    assert fresh.teacher_loaded and fresh.num_updates == 1
    for key, value in saved["actor_state_dict"].items():
        assert torch.equal(fresh.actor.state_dict()[key], value)


def test_linear_ramp_curriculum() -> None:
    """The ramp is constant outside [begin, finish] and linear inside (hand values)."""
    ramp = LinearRamp(start=0.0, end=1.0, begin=10, finish=20)
    assert [ramp(u) for u in (0, 10, 15, 20, 99)] == [0.0, 0.0, 0.5, 1.0, 1.0]
    step = LinearRamp(start=1.0, end=0.1, begin=5, finish=5)
    assert step(5) == 1.0 and step(6) == 0.1


def test_student_ppo_weight_follows_the_curriculum(student_alg: StudentPPO) -> None:
    """w_PPO and w_dist are read at the current update count."""
    student_alg.w_ppo = LinearRamp(0.0, 1.0, 0, 4)
    student_alg.num_updates = 2
    assert student_alg.policy_loss_weight() == 0.5
