# SPDX-License-Identifier: Apache-2.0
"""GM-Loco student actor: pi(a_t | o_t, z_hat_t), z_hat_t from a temporal-convolution encoder over o_{t-N:t}.

Kamohara et al., arXiv 2603.13707, Sec. IV-B. The student feels the ground only through its own joints: three
1-D convolutions and one MLP read the N-step proprioceptive history and estimate the teacher's terrain latent.
Selected in rsl-rl with ``class_name="gmloco.train.teacher_student.student:StudentActor"``.

History length: the paper does not give N; we use N = 50 frames, i.e. 1.0 s at the 50 Hz policy rate, which spans
about two gait cycles of the G1 at walking cadence. The history holds the current frame last (mjlab's
``CircularBuffer`` order, oldest first) and, after a reset, repeats the first frame (mjlab back-fill).
"""

from __future__ import annotations

import torch
import torch.nn as nn
from rsl_rl.modules import MLP, EmpiricalNormalization
from tensordict import TensorDict

from gmloco.train.teacher_student.actor_export import LatentActorExport
from gmloco.train.teacher_student.config import DEFAULT_HISTORY_LENGTH
from gmloco.train.teacher_student.latent_actor import LatentActor
from gmloco.train.teacher_student.networks import TemporalConvEncoder, history_to_time_major

__all__ = ["DEFAULT_HISTORY_LENGTH", "StudentActor"]


class StudentActor(LatentActor):
    """MLP actor over ``[o_t, z_hat_t]`` with a temporal-convolution history encoder.

    It also carries a frozen copy of the teacher's stiffness decoder psi, so the exported policy can report the
    decoded eta = psi(z_hat) next to the action (the adaptation figure and the eta-tracking metric use it). The copy
    never trains: its parameters have ``requires_grad=False``.
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
        history_obs_set: str = "history",
        history_length: int = DEFAULT_HISTORY_LENGTH,
        history_term_dims: tuple[int, ...] | list[int] | None = None,
        history_obs_normalization: bool = True,
        latent_dim: int = 16,
        tcn_channels: tuple[int, ...] | list[int] = (32, 32, 32),
        tcn_kernel_sizes: tuple[int, ...] | list[int] = (8, 5, 5),
        tcn_strides: tuple[int, ...] | list[int] = (4, 1, 1),
        tcn_mlp_hidden_dims: tuple[int, ...] | list[int] = (128,),
        decoder_hidden_dims: tuple[int, ...] | list[int] = (64, 128, 256),
    ) -> None:
        """Build the actor MLP (input ``obs_dim + latent_dim``), the history encoder and the decoder copy.

        Args:
            obs: Observation groups, used for the input sizes.
            obs_groups: rsl-rl observation sets; ``obs_groups[obs_set]`` is o_t and ``obs_groups[history_obs_set]``
                names exactly one history group.
            obs_set: Set of the actor input o_t (``"actor"``).
            output_dim: Number of actions.
            hidden_dims: Actor MLP hidden widths; equal to the teacher's so it can start from the teacher's actor.
            activation: Activation of every MLP and convolution.
            obs_normalization: Normalize o_t with running statistics.
            distribution_cfg: rsl-rl action distribution config.
            history_obs_set: Observation set that holds the history group.
            history_length: N, frames in the history.
            history_term_dims: Per-term frame sizes when the history group is flattened (mjlab term-major layout);
                None when it is ``[num_envs, N, D]``.
            history_obs_normalization: Normalize history frames with per-feature running statistics.
            latent_dim: Size of z_hat; equal to the teacher's latent size.
            tcn_channels: Output channels of the three convolutions.
            tcn_kernel_sizes: Kernel sizes of the three convolutions [frames].
            tcn_strides: Strides of the three convolutions [frames].
            tcn_mlp_hidden_dims: Hidden widths of the MLP after the convolutions.
            decoder_hidden_dims: Widths of the (frozen) decoder copy; equal to the teacher's.

        Raises:
            ValueError: If the history set does not name exactly one group.
        """
        self.latent_dim = latent_dim  # read by _get_latent_dim() inside MLPModel.__init__
        super().__init__(
            obs, obs_groups, obs_set, output_dim, hidden_dims, activation, obs_normalization, distribution_cfg
        )
        groups = list(obs_groups[history_obs_set])
        if len(groups) != 1:
            raise ValueError(f"Observation set '{history_obs_set}' must name exactly one history group, got {groups}.")
        self.history_group = groups[0]
        self.history_length = history_length
        self.history_term_dims = tuple(history_term_dims) if history_term_dims is not None else None
        frame_dim = self.history(obs).shape[-1]
        self.history_frame_dim = frame_dim
        self.history_obs_normalization = history_obs_normalization
        self.history_normalizer = EmpiricalNormalization(frame_dim) if history_obs_normalization else nn.Identity()
        self.encoder = TemporalConvEncoder(
            history_length,
            frame_dim,
            latent_dim,
            tuple(tcn_channels),
            tuple(tcn_kernel_sizes),
            tuple(tcn_strides),
            tuple(tcn_mlp_hidden_dims),
            activation,
        )
        self.decoder = MLP(latent_dim, 1, tuple(decoder_hidden_dims), activation).requires_grad_(False)
        self.latent: torch.Tensor | None = None
        """Latent estimate z_hat of the last forward pass, ``[batch, latent_dim]``."""

    def history(self, obs: TensorDict) -> torch.Tensor:
        """Return the raw history ``[batch, N, D]``, oldest frame first."""
        return history_to_time_major(obs[self.history_group], self.history_length, self.history_term_dims)

    def encode(self, obs: TensorDict) -> torch.Tensor:
        """Return z_hat ``[batch, latent_dim]`` from the normalized history."""
        return self.encoder(self.history_normalizer(self.history(obs)))

    def decode(self, z: torch.Tensor) -> torch.Tensor:
        """Return psi(z) ``[batch, 1]`` with the frozen decoder copy."""
        return self.decoder(z)

    def latent_for_actor(self, obs: TensorDict) -> torch.Tensor:
        """Return z_hat ``[batch, latent_dim]`` and keep it as :attr:`latent` for the distillation loss."""
        self.latent = self.encode(obs)
        return self.latent

    def update_normalization(self, obs: TensorDict) -> None:
        """Update the o_t and per-frame history running statistics."""
        super().update_normalization(obs)
        if self.history_obs_normalization:
            self.history_normalizer.update(self.history(obs).reshape(-1, self.history_frame_dim))  # type: ignore[operator]

    def export_copy(self, onnx: bool) -> nn.Module:
        """Return ``(obs, history) -> actions``, or for ONNX the outputs ``actions``, ``latent``, ``eta``."""
        return _StudentOnnxExport(self) if onnx else _StudentExport(self)


class _StudentExport(LatentActorExport):
    """Deterministic student: ``(obs [B, obs_dim], history [B, N, D]) -> actions [B, A]``."""

    def __init__(self, model: StudentActor) -> None:
        """Deep-copy every module on the action path (encoder included), the history normalizer and the decoder."""
        shape = (model.history_length, model.history_frame_dim)
        super().__init__(model, model.history_normalizer, "history", shape)

    def forward(self, obs: torch.Tensor, history: torch.Tensor) -> torch.Tensor:
        """Return the deterministic action ``[B, A]``."""
        return self._act(obs, history)[0]

    def _act(self, obs: torch.Tensor, history: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Return ``(actions [B, A], z_hat [B, latent_dim])``."""
        z_hat = self.encode(history)
        return self.act(obs, z_hat), z_hat


class _StudentOnnxExport(_StudentExport):
    """ONNX student with diagnostics: ``(obs, history) -> (actions [B, A], latent [B, Z], eta [B, 1])``."""

    def forward(self, obs: torch.Tensor, history: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:  # type: ignore[override]
        """Return the action, z_hat and the decoded stiffness psi(z_hat)."""
        actions, z_hat = self._act(obs, history)
        return actions, z_hat, self.decoder(z_hat)

    @property
    def output_names(self) -> list[str]:
        """Return the ONNX output names."""
        return ["actions", "latent", "eta"]
