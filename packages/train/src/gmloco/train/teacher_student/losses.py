# SPDX-License-Identifier: Apache-2.0
"""Loss terms of the GM-Loco teacher and student (Kamohara et al., arXiv 2603.13707, Sec. IV).

Teacher: L = L_PPO + (eta - psi(z))^2 + beta * KL(q(z | s_t, o_{t-N:t}) || N(0, I)).
Student: L = w_PPO * L_PPO + w_dist * ||a - a_hat||^2 + ||z - z_hat||^2 + (psi(z) - psi(z_hat))^2.

Squared norms are summed over their vector dimension and averaged over the batch; every function returns scalars.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch

from gmloco.train.teacher_student.networks import kl_standard_normal

__all__ = [
    "DistillTerms",
    "VaeTerms",
    "distill_terms",
    "squared_error",
    "surrogate_loss",
    "vae_terms",
    "value_loss",
]


def squared_error(x: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
    """Return mean_b ||x_b - y_b||^2 for ``x``, ``y`` of shape ``[batch, dim]``."""
    return (x - y).pow(2).sum(dim=-1).mean()


def surrogate_loss(
    log_prob: torch.Tensor, old_log_prob: torch.Tensor, advantages: torch.Tensor, clip: float
) -> torch.Tensor:
    """Clipped PPO surrogate (Schulman et al. 2017, eq. 7), negated for minimisation.

    Args:
        log_prob: log pi(a|s) under the current policy, ``[batch]``.
        old_log_prob: log pi_old(a|s) stored at rollout, ``[batch]`` or ``[batch, 1]``.
        advantages: Advantage estimates, ``[batch]`` or ``[batch, 1]``.
        clip: Ratio clip epsilon.
    """
    ratio = torch.exp(log_prob - old_log_prob.reshape(log_prob.shape))
    adv = advantages.reshape(log_prob.shape)
    return torch.max(-adv * ratio, -adv * ratio.clamp(1.0 - clip, 1.0 + clip)).mean()


def value_loss(
    values: torch.Tensor, old_values: torch.Tensor, returns: torch.Tensor, clip: float, clipped: bool
) -> torch.Tensor:
    """Value regression loss, optionally clipped around the rollout values; all inputs ``[batch, 1]``."""
    if not clipped:
        return (returns - values).pow(2).mean()
    values_clipped = old_values + (values - old_values).clamp(-clip, clip)
    return torch.max((values - returns).pow(2), (values_clipped - returns).pow(2)).mean()


@dataclass
class VaeTerms:
    """Teacher auxiliary losses on one batch (scalars)."""

    reconstruction: torch.Tensor
    """mean_b (eta_b - psi(z_b))^2, z sampled with the reparameterisation trick."""
    kl: torch.Tensor
    """mean_b KL(N(mu_b, sigma_b^2) || N(0, I)) [nats]."""


def vae_terms(
    eta: torch.Tensor, mu: torch.Tensor, logvar: torch.Tensor, decoder: torch.nn.Module, sample: bool = True
) -> VaeTerms:
    """Return the teacher's reconstruction and KL terms.

    Args:
        eta: Normalized stiffness target, ``[batch, 1]``.
        mu: Latent mean, ``[batch, latent_dim]``.
        logvar: Latent log-variance, ``[batch, latent_dim]``.
        decoder: psi, maps ``[batch, latent_dim]`` to ``[batch, 1]``.
        sample: Decode a reparameterised sample (VAE training) instead of the mean.
    """
    z = mu + torch.exp(0.5 * logvar) * torch.randn_like(mu) if sample else mu
    return VaeTerms(reconstruction=squared_error(decoder(z), eta), kl=kl_standard_normal(mu, logvar).mean())


@dataclass
class DistillTerms:
    """Student supervised losses on one batch (scalars)."""

    action: torch.Tensor
    """mean_b ||a_b - a_hat_b||^2: student mean action vs. the teacher's label."""
    latent: torch.Tensor
    """mean_b ||z_b - z_hat_b||^2: teacher latent mean vs. the student's estimate."""
    decoded: torch.Tensor
    """mean_b (psi(z_b) - psi(z_hat_b))^2 through the frozen decoder."""


def distill_terms(
    student_action: torch.Tensor,
    teacher_action: torch.Tensor,
    z_teacher: torch.Tensor,
    z_student: torch.Tensor,
    decoder: torch.nn.Module,
) -> DistillTerms:
    """Return the student's action, latent and decoded-stiffness terms (teacher tensors are targets, no grad).

    Args:
        student_action: Student deterministic action, ``[batch, num_actions]``.
        teacher_action: Teacher deterministic action on the same states, ``[batch, num_actions]``.
        z_teacher: Teacher latent mean, ``[batch, latent_dim]``.
        z_student: Student latent estimate, ``[batch, latent_dim]``.
        decoder: Frozen teacher decoder psi; gradients flow through it into ``z_student`` only.
    """
    with torch.no_grad():
        eta_teacher = decoder(z_teacher)
    return DistillTerms(
        action=squared_error(student_action, teacher_action.detach()),
        latent=squared_error(z_student, z_teacher.detach()),
        decoded=squared_error(decoder(z_student), eta_teacher),
    )
