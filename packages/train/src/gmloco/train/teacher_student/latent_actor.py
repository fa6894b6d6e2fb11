# SPDX-License-Identifier: Apache-2.0
"""The actor shape shared by the teacher and the student: an rsl-rl MLP over ``[o_t, z]``.

Both actors feed the normalized observation o_t, concatenated with a terrain latent z from an encoder, to the
actor MLP. They differ in the encoder (VAE over privileged state and history for the teacher, temporal convolutions
over the raw history for the student), in what they keep of the last latent for their losses, and in the export
copy they hand to rsl-rl's ``as_jit`` / ``as_onnx``.
"""

from __future__ import annotations

import torch
import torch.nn as nn
from rsl_rl.models import MLPModel
from rsl_rl.modules import HiddenState
from tensordict import TensorDict

__all__ = ["LatentActor"]


class LatentActor(MLPModel):
    """MLP actor over ``[o_t, z]``: o_t from rsl-rl's ``MLPModel``, z from :meth:`latent_for_actor`.

    Subclasses set :attr:`latent_dim`, build their encoder after ``super().__init__``, and define
    :meth:`latent_for_actor` and :meth:`export_copy`.
    """

    latent_dim: int
    """Size of z; a subclass sets it before ``super().__init__``, which sizes the actor MLP from it."""

    def _get_latent_dim(self) -> int:
        """Return the actor MLP input size, ``obs_dim + latent_dim``."""
        return self.obs_dim + self.latent_dim

    def latent_for_actor(self, obs: TensorDict) -> torch.Tensor:
        """Return the latent z the actor reads, ``[batch, latent_dim]``, keeping what the losses need of it."""
        raise NotImplementedError

    def export_copy(self, onnx: bool) -> nn.Module:
        """Return the deterministic export copy; ``onnx`` selects the one with the ONNX outputs."""
        raise NotImplementedError

    def get_latent(
        self, obs: TensorDict, masks: torch.Tensor | None = None, hidden_state: HiddenState = None
    ) -> torch.Tensor:
        """Return the actor input ``[batch, obs_dim + latent_dim]``: normalized o_t and the terrain latent."""
        o_t = super().get_latent(obs, masks, hidden_state)
        return torch.cat([o_t, self.latent_for_actor(obs)], dim=-1)

    def as_jit(self) -> nn.Module:
        """Return a TorchScript-ready copy that keeps the encoder: ``(obs, <encoder input>) -> actions``."""
        return self.export_copy(onnx=False)

    def as_onnx(self, verbose: bool) -> nn.Module:
        """Return an ONNX-ready copy that keeps the encoder: inputs ``obs`` and the encoder's input."""
        return self.export_copy(onnx=True)
