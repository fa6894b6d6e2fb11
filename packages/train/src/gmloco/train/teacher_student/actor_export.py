# SPDX-License-Identifier: Apache-2.0
"""The export copy shared by the teacher and the student: a deterministic actor over ``[o_t, z]``.

Both actors act on the normalized observation o_t concatenated with a terrain latent z from an encoder; their
export modules (``as_jit`` / ``as_onnx``) differ only in the encoder's input (privileged state and history for
the teacher, the raw history for the student), in what the encoder returns and in their outputs.
"""

from __future__ import annotations

import copy
from typing import Any

import torch
import torch.nn as nn

__all__ = ["LatentActorExport"]


class LatentActorExport(nn.Module):
    """Deep copies of an actor's action path: o_t normalizer, encoder and its input normalizer, decoder, MLP, head.

    Inputs ``(obs [B, obs_dim], <encoder input> [B, *encoder_input_shape])``. Subclasses define ``forward``;
    :meth:`encode` runs the encoder on its raw input and :meth:`act` maps o_t and a latent to the action.
    """

    is_recurrent: bool = False

    def __init__(
        self, model: Any, encoder_normalizer: nn.Module, encoder_input_name: str, encoder_input_shape: tuple[int, ...]
    ) -> None:
        """Deep-copy every module on the action path of ``model`` (a teacher or student actor).

        Args:
            model: The actor.
            encoder_normalizer: The actor's normalizer of the encoder input (copied as ``encoder_normalizer``).
            encoder_input_name: Name of the second input (ONNX input name).
            encoder_input_shape: Shape of one sample of the second input.
        """
        super().__init__()
        self.obs_normalizer = copy.deepcopy(model.obs_normalizer)
        self.encoder = copy.deepcopy(model.encoder)
        self.decoder = copy.deepcopy(model.decoder)
        self.mlp = copy.deepcopy(model.mlp)
        dist = model.distribution
        self.deterministic_output = dist.as_deterministic_output_module() if dist is not None else nn.Identity()
        self.encoder_normalizer = copy.deepcopy(encoder_normalizer)
        self.obs_dim: int = model.obs_dim
        self.encoder_input_name = encoder_input_name
        self.encoder_input_shape = encoder_input_shape

    def encode(self, encoder_input: torch.Tensor):  # noqa: ANN201 (the encoder's output: TorchScript infers it)
        """Return the encoder's output for its raw input ``[B, *encoder_input_shape]`` (normalized first)."""
        return self.encoder(self.encoder_normalizer(encoder_input))

    def act(self, obs: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        """Return the deterministic action ``[B, A]`` for o_t ``[B, obs_dim]`` and a latent ``[B, Z]``."""
        return self.deterministic_output(self.mlp(torch.cat([self.obs_normalizer(obs), z], dim=-1)))

    @torch.jit.export
    def reset(self) -> None:
        """No recurrent state to reset (the caller keeps any history)."""

    def get_dummy_inputs(self) -> tuple[torch.Tensor, torch.Tensor]:
        """Return zero inputs of batch 1 for tracing."""
        return torch.zeros(1, self.obs_dim), torch.zeros(1, *self.encoder_input_shape)

    @property
    def input_names(self) -> list[str]:
        """Return the ONNX input names."""
        return ["obs", self.encoder_input_name]

    @property
    def output_names(self) -> list[str]:
        """Return the ONNX output names."""
        return ["actions"]
