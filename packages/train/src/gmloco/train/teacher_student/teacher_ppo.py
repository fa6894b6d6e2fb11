# SPDX-License-Identifier: Apache-2.0
"""PPO for the GM-Loco teacher: L = L_PPO + (eta - psi(z))^2 + beta * KL(q(z | .) || N(0, I)).

Kamohara et al., arXiv 2603.13707, Sec. IV-A. Selected in rsl-rl with
``class_name="gmloco.train.teacher_student.teacher_ppo:TeacherPPO"``; rsl-rl's own ``PPO.construct_algorithm``
builds it, with :class:`~gmloco.train.teacher_student.teacher.TeacherActor` as the actor.
"""

from __future__ import annotations

import torch
from rsl_rl.storage import RolloutStorage
from tensordict import TensorDict

from gmloco.train.teacher_student.aux_ppo import AuxLossPPO
from gmloco.train.teacher_student.losses import vae_terms
from gmloco.train.teacher_student.teacher import TeacherActor

__all__ = ["TeacherPPO", "batch_r2", "eta_target"]


def eta_target(obs: TensorDict, group: str, index: int) -> torch.Tensor:
    """Return the normalized stiffness eta, ``[batch, 1]``, read from column ``index`` of group ``group``."""
    return obs[group][:, [index]]


def batch_r2(predicted: torch.Tensor, target: torch.Tensor) -> float:
    """R^2 of ``predicted`` against ``target`` (both ``[batch, 1]``) on one mini-batch; nan if the target is constant.

    Logged per mini-batch and averaged over the update (``Loss/eta_r2`` in TensorBoard), so it tracks the
    decoded-eta quality during training; the held-out evaluation computes the pooled R^2 instead.
    """
    ss_tot = (target - target.mean()).pow(2).sum()
    ss_res = (target - predicted).pow(2).sum()
    return float(1.0 - ss_res / ss_tot) if float(ss_tot) > 0.0 else float("nan")


class TeacherPPO(AuxLossPPO):
    """PPO whose actor is a :class:`TeacherActor`, trained jointly with its VAE terrain encoder."""

    actor: TeacherActor

    def __init__(
        self,
        actor: TeacherActor,
        critic: torch.nn.Module,
        storage: RolloutStorage,
        eta_group: str = "critic",
        eta_index: int = -1,
        kl_weight: float = 1e-3,
        reconstruction_weight: float = 1.0,
        decoder_learning_rate: float | None = 1e-3,
        **kwargs: object,
    ) -> None:
        """Initialise PPO and the VAE loss weights.

        Args:
            actor: Teacher actor with encoder and decoder.
            critic: Asymmetric critic (a plain rsl-rl ``MLPModel`` on the privileged group).
            storage: Rollout storage (rsl-rl keeps every observation group, privileged ones included).
            eta_group: Observation group that holds eta = xi / xi_max.
            eta_index: Column of eta in that group.
            kl_weight: beta, weight of the KL term.
            reconstruction_weight: Weight of (eta - psi(z))^2 (1 in the paper).
            decoder_learning_rate: Fixed Adam learning rate of the eta decoder (None: the policy's adaptive one).
                The encoder always follows the policy's KL-adaptive rate: its latent feeds the actor, so it is part
                of the policy the KL measures.
            **kwargs: rsl-rl PPO arguments.

        Raises:
            TypeError: If the actor has no encoder/decoder (a stock ``MLPModel``).
        """
        if not isinstance(actor, TeacherActor):
            raise TypeError(f"TeacherPPO needs a TeacherActor, got {type(actor).__name__}.")
        super().__init__(actor, critic, storage, **kwargs)  # type: ignore[arg-type]
        self.eta_group = eta_group
        self.eta_index = eta_index
        self.kl_weight = kl_weight
        self.reconstruction_weight = reconstruction_weight
        if decoder_learning_rate is not None:
            self.split_fixed_lr_group([actor.decoder], decoder_learning_rate)

    def auxiliary_loss(self, batch: RolloutStorage.Batch) -> tuple[torch.Tensor, dict[str, float]]:
        """Return ``w_rec * (eta - psi(z))^2 + beta * KL`` on the latent of the preceding actor forward."""
        mu, logvar = self.actor.latent_mu, self.actor.latent_logvar
        assert mu is not None and logvar is not None, "the actor forward must run before auxiliary_loss()"
        eta = eta_target(batch.observations, self.eta_group, self.eta_index)  # type: ignore[arg-type]
        terms = vae_terms(eta, mu, logvar, self.actor.decoder)
        loss = self.reconstruction_weight * terms.reconstruction + self.kl_weight * terms.kl
        with torch.no_grad():
            r2 = batch_r2(self.actor.decoder(mu), eta)
        return loss, {"eta_reconstruction": terms.reconstruction.item(), "latent_kl": terms.kl.item(), "eta_r2": r2}
