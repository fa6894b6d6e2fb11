# SPDX-License-Identifier: Apache-2.0
"""The policy-KL probes on a filled toy rollout: zero-step KL, gradient norms by group, KL by groups stepped."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
import torch
from rsl_rl.env import VecEnv

from gmloco.train.teacher_student import ObsGroupsCfg, TeacherCfg, TeacherPPO
from gmloco.train.teacher_student.kl_probe import (
    grad_norms_by_loss,
    kl_stepping_only,
    param_groups,
    std_gradients_by_loss,
    zero_step_kls,
)
from gmloco.train.teacher_student.kl_probe_cli import main


@pytest.fixture
def filled(toy_env: VecEnv, teacher_cfg: TeacherCfg, runner_cfg: Callable[[dict], dict]) -> TeacherPPO:
    """A toy teacher whose storage holds 4 steps of 16 envs, collected with frozen normalizers."""
    torch.manual_seed(0)
    entries = runner_cfg(teacher_cfg.to_rsl_rl(ObsGroupsCfg()))
    alg: TeacherPPO = TeacherPPO.construct_algorithm(toy_env.get_observations(), toy_env, entries, "cpu")  # type: ignore[assignment]
    alg.train_mode()
    alg.actor.obs_normalizer.eval()
    alg.actor.encoder_normalizer.eval()
    obs = toy_env.get_observations()
    with torch.inference_mode():
        for _ in range(4):
            obs, rew, dones, extras = toy_env.step(alg.act(obs))
            alg.process_env_step(obs, rew, dones, extras)
        alg.compute_returns(obs)
    return alg


def test_zero_step_kl_is_exactly_zero(filled: TeacherPPO) -> None:
    """Mean latent, frozen normalizers: the recomputed policy is the acting one, mini-batch by mini-batch."""
    assert zero_step_kls(filled) == [0.0] * filled.num_mini_batches


def test_grad_norms_reach_only_the_groups_each_loss_feeds(filled: TeacherPPO) -> None:
    """Surrogate: policy + encoder; value: critic; VAE terms: encoder + decoder (the decoder is off the action path)."""
    batch = next(iter(filled.storage.mini_batch_generator(filled.num_mini_batches, 1)))
    norms = grad_norms_by_loss(filled, batch)
    assert norms["surrogate"]["policy"] > 0 and norms["surrogate"]["encoder"] > 0
    assert norms["surrogate"]["decoder"] == 0 and norms["surrogate"]["critic"] == 0
    assert norms["value"]["critic"] > 0 and norms["value"]["policy"] == 0
    assert norms["vae"]["encoder"] > 0 and norms["vae"]["decoder"] > 0 and norms["vae"]["policy"] == 0
    assert all(p.grad is None or not p.grad.any() for ps in param_groups(filled).values() for p in ps)


def test_std_gradient_of_the_entropy_bonus_is_analytic(filled: TeacherPPO) -> None:
    """d(-c H)/d sigma = -c / sigma per action dim (H sums ln sigma over dims); the value loss does not reach sigma."""
    grads = std_gradients_by_loss(filled)
    (name, param), *_ = filled.actor.distribution.named_parameters()  # type: ignore[union-attr]
    assert name == "std_param"  # std_type "scalar": sigma itself is the parameter
    c = filled.policy_loss_weight() * filled.entropy_coef
    assert grads["entropy_bonus"][name] == pytest.approx(-c * float((1.0 / param.detach()).mean()), rel=1e-5)
    assert grads["value"][name] == 0.0 and grads["surrogate"][name] != 0.0
    assert param.grad is None or not param.grad.any()


def test_stepping_only_the_decoder_leaves_the_policy(filled: TeacherPPO) -> None:
    """The decoder moves no action: KL 0 after every step; the policy's own step moves it; state is restored."""
    weights = [p.detach().clone() for p in filled.actor.parameters()]
    lr = filled.learning_rate
    assert kl_stepping_only(filled, ["decoder"], 1e-3, 3) == [0.0, 0.0, 0.0]
    moved = kl_stepping_only(filled, ["policy"], 1e-3, 3)
    assert 0.0 < moved[0] < moved[-1], moved
    assert all(torch.equal(a, b) for a, b in zip(weights, filled.actor.parameters(), strict=True))
    assert filled.learning_rate == lr and zero_step_kls(filled) == [0.0] * filled.num_mini_batches


def test_unknown_group_is_refused(filled: TeacherPPO) -> None:
    """A group name outside policy / encoder / decoder / critic raises with the valid names."""
    with pytest.raises(ValueError, match="unknown parameter groups"):
        kl_stepping_only(filled, ["mlp"], 1e-3, 1)


def test_cli_refuses_a_folder_without_checkpoint(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Bad input exits with status 2 and names the missing file."""
    with pytest.raises(SystemExit) as exc:
        main(["--artifact", str(tmp_path)])
    assert exc.value.code == 2 and "checkpoint.pt" in capsys.readouterr().err
