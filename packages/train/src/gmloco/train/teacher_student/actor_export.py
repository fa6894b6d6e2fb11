# SPDX-License-Identifier: Apache-2.0
"""The export copy shared by the teacher and the student: a deterministic actor over ``[o_t, z]``.

Both actors act on the normalized observation o_t concatenated with a terrain latent z from an encoder; their
export modules (``as_jit`` / ``as_onnx``) differ only in the encoder's input (privileged state and history for
the teacher, the raw history for the student) and in their outputs.
"""

from __future__ import annotations

import copy
from typing import Any

import torch
import torch.nn as nn

__all__ = ["LatentActorExport"]


class LatentActorExport(nn.Module):
    """Deep copies of an actor's action path (o_t normalizer, encoder, decoder, MLP, deterministic head).

    Subclasses copy the encoder's input normalizer, and define ``forward``, ``get_dummy_inputs`` and
    ``input_names``; :meth:`act` maps o_t and a latent to the action.
    """

    is_recurrent: bool = False

    def __init__(self, model: Any) -> None:
        """Deep-copy every module on the action path of ``model`` (a teacher or student actor)."""
        super().__init__()
        self.obs_normalizer = copy.deepcopy(model.obs_normalizer)
        self.encoder = copy.deepcopy(model.encoder)
        self.decoder = copy.deepcopy(model.decoder)
        self.mlp = copy.deepcopy(model.mlp)
        dist = model.distribution
        self.deterministic_output = dist.as_deterministic_output_module() if dist is not None else nn.Identity()
        self.obs_dim: int = model.obs_dim

    def act(self, obs: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        """Return the deterministic action ``[B, A]`` for o_t ``[B, obs_dim]`` and a latent ``[B, Z]``."""
        return self.deterministic_output(self.mlp(torch.cat([self.obs_normalizer(obs), z], dim=-1)))

    @torch.jit.export
    def reset(self) -> None:
        """No recurrent state to reset (the caller keeps any history)."""

    @property
    def output_names(self) -> list[str]:
        """Return the ONNX output names."""
        return ["actions"]
