# SPDX-License-Identifier: Apache-2.0
"""GM-Loco teacher actor: pi(a_t | o_t, z_t) with a VAE terrain encoder and an eta decoder.

Kamohara et al., arXiv 2603.13707, Sec. IV-A: the encoder phi_teacher(z | s_t, o_{t-N:t}) sees the privileged
state and the proprioceptive history, the decoder psi(z) reconstructs only the normalized stiffness
eta = xi / xi_max, and the actor sees o_t and z_t. Selected in rsl-rl with
``class_name="gmloco.train.teacher_student.teacher:TeacherActor"``.
"""

from __future__ import annotations

from typing import Literal

import torch
import torch.nn as nn
from rsl_rl.modules import MLP, EmpiricalNormalization
from tensordict import TensorDict

from gmloco.train.teacher_student.actor_export import LatentActorExport
from gmloco.train.teacher_student.latent_actor import LatentActor
from gmloco.train.teacher_student.networks import GaussianEncoder, flatten_groups

__all__ = ["TeacherActor"]


class TeacherActor(LatentActor):
    """MLP actor over ``[o_t, z_t]`` with a Gaussian terrain encoder and a stiffness decoder.

    The encoder input is the concatenation of the observation groups of the ``encoder_obs_set`` set
    (e.g. ``["critic", "history"]``); 3-D history groups ``[num_envs, N, D]`` are flattened. After each forward
    pass the latent statistics of that pass are kept in :attr:`latent_mu` / :attr:`latent_logvar` (the same way
    rsl-rl keeps the last action distribution), so the algorithm can add the VAE loss without a second pass.
    """

    def __init__(
        self,
        obs: TensorDict,
        obs_groups: dict[str, list[str]],
        obs_set: str,
        output_dim: int,
        hidden_dims: tuple[int, ...] | list[int] = (512, 256, 128),
        activation: str = "elu",
        obs_normalization: bool = False,
        distribution_cfg: dict | None = None,
        encoder_obs_set: str = "encoder",
        encoder_hidden_dims: tuple[int, ...] | list[int] = (256, 128, 64),
        decoder_hidden_dims: tuple[int, ...] | list[int] = (64, 128, 256),
        latent_dim: int = 16,
        encoder_history_steps: int | None = None,
        encoder_obs_normalization: bool = True,
        actor_latent: Literal["mean", "sample"] = "mean",
    ) -> None:
        """Build the actor MLP (input ``obs_dim + latent_dim``), the encoder and the decoder.

        Args:
            obs: Observation groups, used for the input sizes.
            obs_groups: rsl-rl observation sets; ``obs_groups[obs_set]`` is o_t, ``obs_groups[encoder_obs_set]``
                the encoder input.
            obs_set: Set of the actor input o_t (``"actor"`` in PPO, ``"teacher"`` in distillation).
            output_dim: Number of actions.
            hidden_dims: Actor MLP hidden widths (GM-Loco: 512, 256, 128).
            activation: Activation of every MLP (GM-Loco: ELU).
            obs_normalization: Normalize o_t with running statistics.
            distribution_cfg: rsl-rl action distribution config (None: deterministic).
            encoder_obs_set: Observation set fed to the encoder.
            encoder_hidden_dims: Encoder MLP widths (GM-Loco: 256, 128, 64).
            decoder_hidden_dims: Decoder MLP widths (GM-Loco: 64, 128, 256).
            latent_dim: Size of z (not given by the paper; 16 by default).
            encoder_history_steps: Keep only the newest frames of 3-D history groups (None: all N).
            encoder_obs_normalization: Normalize the encoder input with running statistics.
            actor_latent: ``"mean"`` feeds mu to the actor (deterministic in z, so the PPO ratio is exact);
                ``"sample"`` feeds a reparameterised sample in training mode (the PPO ratio then carries latent noise).
        """
        self.latent_dim = latent_dim  # read by _get_latent_dim() inside MLPModel.__init__
        super().__init__(
            obs, obs_groups, obs_set, output_dim, hidden_dims, activation, obs_normalization, distribution_cfg
        )
        self.encoder_obs_groups = list(obs_groups[encoder_obs_set])
        self.encoder_history_steps = encoder_history_steps
        self.encoder_obs_normalization = encoder_obs_normalization
        self.actor_latent = actor_latent
        enc_dim = flatten_groups(obs, self.encoder_obs_groups, encoder_history_steps).shape[-1]
        self.encoder_obs_dim = enc_dim
        self.encoder_normalizer = EmpiricalNormalization(enc_dim) if encoder_obs_normalization else nn.Identity()
        self.encoder = GaussianEncoder(enc_dim, latent_dim, tuple(encoder_hidden_dims), activation)
        self.decoder = MLP(latent_dim, 1, tuple(decoder_hidden_dims), activation)
        self.latent_mu: torch.Tensor | None = None
        """Latent mean of the last forward pass, ``[batch, latent_dim]``."""
        self.latent_logvar: torch.Tensor | None = None
        """Latent log-variance of the last forward pass, ``[batch, latent_dim]``."""

    def encoder_input(self, obs: TensorDict) -> torch.Tensor:
        """Return the flattened, un-normalized encoder input ``[batch, encoder_obs_dim]``."""
        return flatten_groups(obs, self.encoder_obs_groups, self.encoder_history_steps)

    def encode(self, obs: TensorDict) -> tuple[torch.Tensor, torch.Tensor]:
        """Return ``(mu, logvar)`` of q(z | s_t, o_{t-N:t}), each ``[batch, latent_dim]``."""
        return self.encoder(self.encoder_normalizer(self.encoder_input(obs)))

    def decode(self, z: torch.Tensor) -> torch.Tensor:
        """Return the decoded normalized stiffness psi(z), ``[batch, 1]``."""
        return self.decoder(z)

    def latent_for_actor(self, obs: TensorDict) -> torch.Tensor:
        """Return z ``[batch, latent_dim]`` (mu, or a training-mode sample) and keep mu and logvar for the VAE loss."""
        mu, logvar = self.encode(obs)
        self.latent_mu, self.latent_logvar = mu, logvar
        use_sample = self.actor_latent == "sample" and self.training
        return mu + torch.exp(0.5 * logvar) * torch.randn_like(mu) if use_sample else mu

    def update_normalization(self, obs: TensorDict) -> None:
        """Update the o_t and encoder-input running statistics."""
        super().update_normalization(obs)
        if self.encoder_obs_normalization:
            self.encoder_normalizer.update(self.encoder_input(obs))  # type: ignore[operator]

    def export_copy(self, onnx: bool) -> nn.Module:
        """Return the same copy for TorchScript and ONNX: ``(obs, encoder_obs) -> actions``."""
        return _TeacherExport(self)


class _TeacherExport(LatentActorExport):
    """Deterministic teacher for export: ``(obs [B, obs_dim], encoder_obs [B, enc_dim]) -> actions [B, A]``."""

    def __init__(self, model: TeacherActor) -> None:
        """Deep-copy every module on the action path, the encoder and its input normalizer included."""
        super().__init__(model, model.encoder_normalizer, "encoder_obs", (model.encoder_obs_dim,))

    def forward(self, obs: torch.Tensor, encoder_obs: torch.Tensor) -> torch.Tensor:
        """Return the deterministic action, using the latent mean."""
        mu, _ = self.encode(encoder_obs)
        return self.act(obs, mu)
