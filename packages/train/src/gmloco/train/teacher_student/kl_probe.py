# SPDX-License-Identifier: Apache-2.0
"""Probes of the teacher's policy KL during a PPO update, the signal of rsl-rl's KL-adaptive learning rate.

Each probe works on a :class:`TeacherPPO` whose rollout storage is filled (after ``compute_returns``):

* :func:`zero_step_kls`: KL(stored || recomputed) of each mini-batch before any optimizer step; anything above
  the normalizers' drift means the update sees another policy than the one that acted.
* :func:`grad_norms_by_loss`: gradient L2 norm of each loss term on each parameter group.
* :func:`kl_stepping_only`: the KL that ``steps`` optimizer steps at rate ``lr`` produce when only some
  parameter groups move; the algorithm's weights and optimizer state are restored afterwards.

``python -m gmloco.train.teacher_student.kl_probe --artifact artifacts/<teacher>`` runs all three on the
committed teacher's env and checkpoint at CPU scale and prints JSON.
"""

from __future__ import annotations

import copy
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

import torch
import torch.nn as nn
from rsl_rl.storage import RolloutStorage

from gmloco.train.teacher_student.teacher_ppo import TeacherPPO

__all__ = ["PARAM_GROUPS", "grad_norms_by_loss", "kl_stepping_only", "param_groups", "zero_step_kls"]

PARAM_GROUPS = ("policy", "encoder", "decoder", "critic")
"""Parameter groups: actor MLP + action std, terrain encoder, eta decoder, critic."""


def param_groups(alg: TeacherPPO) -> dict[str, list[nn.Parameter]]:
    """Return the parameters of each group of :data:`PARAM_GROUPS`."""
    actor = alg.actor
    policy = list(actor.mlp.parameters()) + list(actor.distribution.parameters())  # type: ignore[union-attr]
    return {
        "policy": policy,
        "encoder": list(actor.encoder.parameters()),
        "decoder": list(actor.decoder.parameters()),
        "critic": list(alg.critic.parameters()),
    }


def _batches(alg: TeacherPPO) -> list[RolloutStorage.Batch]:
    """The mini-batches of one epoch over the filled storage."""
    return list(alg.storage.mini_batch_generator(alg.num_mini_batches, 1))


def _kl(alg: TeacherPPO, batch: RolloutStorage.Batch) -> float:
    """Mean KL(stored || current) of the policy on ``batch`` [nats]."""
    with torch.inference_mode():
        alg.actor(batch.observations, stochastic_output=True)
        kl = alg.actor.get_kl_divergence(batch.old_distribution_params, alg.actor.output_distribution_params)  # type: ignore[arg-type]
    return float(kl.mean())


def zero_step_kls(alg: TeacherPPO) -> list[float]:
    """Return each mini-batch's KL(stored || recomputed) [nats] with no optimizer step taken."""
    return [_kl(alg, batch) for batch in _batches(alg)]


def _losses(alg: TeacherPPO, batch: RolloutStorage.Batch) -> dict[str, torch.Tensor]:
    """The weighted loss terms of :meth:`AuxLossPPO.update` on one mini-batch (the rate is not adapted)."""
    schedule, alg.schedule = alg.schedule, "fixed"
    try:
        surrogate, value, entropy = alg._ppo_terms(batch)
    finally:
        alg.schedule = schedule
    aux, _ = alg.auxiliary_loss(batch)
    w_ppo = alg.policy_loss_weight()
    return {
        "surrogate": w_ppo * surrogate,
        "entropy_bonus": -w_ppo * alg.entropy_coef * entropy,
        "value": alg.value_loss_coef * value,
        "vae": aux,
    }


def grad_norms_by_loss(alg: TeacherPPO, batch: RolloutStorage.Batch) -> dict[str, dict[str, float]]:
    """Return ``{loss term: {group: gradient L2 norm}}`` on ``batch``, before clipping."""
    groups = param_groups(alg)
    out: dict[str, dict[str, float]] = {}
    for name, loss in _losses(alg, batch).items():
        alg.optimizer.zero_grad()
        loss.backward(retain_graph=True)
        out[name] = {g: float(torch.sqrt(sum((p.grad.pow(2).sum() for p in ps if p.grad is not None), torch.zeros(())))) for g, ps in groups.items()}  # fmt: skip
    alg.optimizer.zero_grad()
    return out


def std_gradients_by_loss(alg: TeacherPPO) -> dict[str, dict[str, float]]:
    """Return ``{loss term: {distribution parameter: mean d loss / d parameter}}`` over every mini-batch.

    Signed, averaged over the action dimensions and the mini-batches of one epoch, before clipping. The optimizer
    steps against the gradient, so a negative value on the std parameter pushes the action std up: with the
    entropy bonus always negative there, the std falls only where the surrogate's positive gradient outweighs it.
    """
    named = dict(alg.actor.distribution.named_parameters())  # type: ignore[union-attr]
    sums: dict[str, dict[str, float]] = {}
    batches = _batches(alg)
    for batch in batches:
        for term, loss in _losses(alg, batch).items():
            alg.optimizer.zero_grad()
            loss.backward(retain_graph=True)
            row = sums.setdefault(term, dict.fromkeys(named, 0.0))
            for name, param in named.items():
                if param.grad is not None:
                    row[name] += float(param.grad.mean()) / len(batches)
    alg.optimizer.zero_grad()
    return sums


@contextmanager
def _restored(alg: TeacherPPO) -> Iterator[None]:
    """Restore actor, critic and optimizer state (and the adaptive rate) on exit."""
    actor, critic = copy.deepcopy(alg.actor.state_dict()), copy.deepcopy(alg.critic.state_dict())
    optimizer, lr = copy.deepcopy(alg.optimizer.state_dict()), alg.learning_rate
    try:
        yield
    finally:
        with torch.inference_mode():  # the normalizer buffers were last written under inference mode
            alg.actor.load_state_dict(actor)
            alg.critic.load_state_dict(critic)
        alg.optimizer.load_state_dict(optimizer)
        alg.learning_rate = lr


def kl_stepping_only(alg: TeacherPPO, groups: Sequence[str], lr: float, steps: int) -> list[float]:
    """Return the KL over the whole rollout [nats] after each of ``steps`` mini-batch steps moving only ``groups``.

    Every step uses the update's full loss and clipping, at rate ``lr`` for the adaptive groups (fixed-rate groups
    keep theirs); parameters outside ``groups`` are put back after each step. Weights and optimizer are restored.
    """
    unknown = set(groups) - set(PARAM_GROUPS)
    if unknown:
        raise ValueError(f"unknown parameter groups {sorted(unknown)}; choose from {PARAM_GROUPS}")
    held = [p for g, ps in param_groups(alg).items() if g not in groups for p in ps]
    batches = _batches(alg)
    kls: list[float] = []
    with _restored(alg):
        for group in alg.optimizer.param_groups:
            group["lr"] = group["lr"] if group.get("fixed_lr", False) else lr
        for i in range(steps):
            kept = [p.detach().clone() for p in held]
            loss = sum(_losses(alg, batches[i % len(batches)]).values())
            alg.optimizer.zero_grad()
            loss.backward()  # type: ignore[union-attr]
            nn.utils.clip_grad_norm_(alg.actor.parameters(), alg.max_grad_norm)
            nn.utils.clip_grad_norm_(alg.critic.parameters(), alg.max_grad_norm)
            alg.optimizer.step()
            with torch.no_grad():
                for p, q in zip(held, kept, strict=True):
                    p.copy_(q)
            kls.append(sum(_kl(alg, b) for b in batches) / len(batches))
    return kls
