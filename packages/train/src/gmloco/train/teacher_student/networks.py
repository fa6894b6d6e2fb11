# SPDX-License-Identifier: Apache-2.0
"""Building blocks of the GM-Loco terrain encoders (Kamohara et al., arXiv 2603.13707, Sec. IV).

* :class:`GaussianEncoder` is the teacher's variational terrain encoder phi_teacher(z | s_t, o_{t-N:t}): an MLP
  whose last hidden layer feeds two linear heads, the latent mean and log-variance.
* :class:`TemporalConvEncoder` is the student's encoder: three 1-D convolutions over the proprioceptive history,
  then one MLP, producing the latent estimate z_hat.
* :func:`history_to_time_major` turns an mjlab history group into ``[num_envs, N, obs_dim]``.
"""

from __future__ import annotations

import torch
import torch.nn as nn
from rsl_rl.modules import MLP
from rsl_rl.utils import resolve_nn_activation
from tensordict import TensorDict

__all__ = [
    "GaussianEncoder",
    "TemporalConvEncoder",
    "flatten_groups",
    "history_to_time_major",
    "kl_standard_normal",
    "reparameterize",
]


class GaussianEncoder(nn.Module):
    """MLP encoder with a diagonal-Gaussian latent head, q(z | x) = N(mu(x), diag(exp(logvar(x))))."""

    def __init__(self, input_dim: int, latent_dim: int, hidden_dims: tuple[int, ...], activation: str) -> None:
        """Build ``input_dim -> hidden_dims -> (mu, logvar)``; the last hidden layer is activated.

        Args:
            input_dim: Size of the flattened encoder input.
            latent_dim: Size of the latent z.
            hidden_dims: Hidden layer widths, e.g. (256, 128, 64) in GM-Loco.
            activation: rsl-rl activation name.
        """
        super().__init__()
        self.trunk = MLP(input_dim, hidden_dims[-1], hidden_dims[:-1], activation, last_activation=activation)
        self.mu_head = nn.Linear(hidden_dims[-1], latent_dim)
        self.logvar_head = nn.Linear(hidden_dims[-1], latent_dim)
        self.latent_dim = latent_dim

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Return ``(mu, logvar)``, each ``[batch, latent_dim]``, for the input ``x`` ``[batch, input_dim]``."""
        h = self.trunk(x)
        # Clamp the log-variance so exp() stays finite early in training.
        return self.mu_head(h), self.logvar_head(h).clamp(-10.0, 10.0)


def reparameterize(mu: torch.Tensor, logvar: torch.Tensor) -> torch.Tensor:
    """Sample z = mu + sigma * eps, eps ~ N(0, I) (Kingma & Welling 2014), differentiable in mu and logvar."""
    return mu + torch.exp(0.5 * logvar) * torch.randn_like(mu)


def kl_standard_normal(mu: torch.Tensor, logvar: torch.Tensor) -> torch.Tensor:
    """KL(N(mu, diag(sigma^2)) || N(0, I)) per sample, summed over latent dims, shape ``[batch]``.

    Closed form (Kingma & Welling 2014, App. B): 0.5 * sum_j (mu_j^2 + sigma_j^2 - 1 - log sigma_j^2).
    """
    return 0.5 * (mu.pow(2) + logvar.exp() - 1.0 - logvar).sum(dim=-1)


class TemporalConvEncoder(nn.Module):
    """Three 1-D convolutions over time followed by one MLP: ``[batch, N, obs_dim] -> [batch, latent_dim]``.

    Convolutions run along the time axis with the observation features as channels, in the spirit of the
    adaptation module of RMA (Kumar et al., RSS 2021) that GM-Loco's student follows.
    """

    def __init__(
        self,
        history_length: int,
        obs_dim: int,
        latent_dim: int,
        channels: tuple[int, ...],
        kernel_sizes: tuple[int, ...],
        strides: tuple[int, ...],
        mlp_hidden_dims: tuple[int, ...],
        activation: str,
    ) -> None:
        """Build the convolution stack and its MLP head.

        Args:
            history_length: N, number of frames in the history.
            obs_dim: Per-frame observation size D.
            latent_dim: Size of the output latent.
            channels: Output channels of the three convolutions.
            kernel_sizes: Kernel sizes (in frames) of the three convolutions.
            strides: Strides (in frames) of the three convolutions.
            mlp_hidden_dims: Hidden widths of the MLP head.
            activation: rsl-rl activation name.

        Raises:
            ValueError: If the layer tuples do not have three entries, or the history is too short for the kernels.
        """
        super().__init__()
        if not len(channels) == len(kernel_sizes) == len(strides) == 3:
            raise ValueError("GM-Loco's student encoder has exactly three 1-D convolutions.")
        layers: list[nn.Module] = []
        in_ch, length = obs_dim, history_length
        for out_ch, k, s in zip(channels, kernel_sizes, strides, strict=True):
            layers += [nn.Conv1d(in_ch, out_ch, kernel_size=k, stride=s), resolve_nn_activation(activation)]
            length = (length - k) // s + 1
            if length < 1:
                raise ValueError(f"history_length={history_length} is too short for kernels {kernel_sizes}.")
            in_ch = out_ch
        self.convs = nn.Sequential(*layers)
        self.flat_dim = in_ch * length
        self.mlp = MLP(self.flat_dim, latent_dim, mlp_hidden_dims, activation)
        self.history_length = history_length
        self.obs_dim = obs_dim

    def forward(self, history: torch.Tensor) -> torch.Tensor:
        """Encode ``history`` ``[batch, N, obs_dim]`` (oldest frame first) into ``[batch, latent_dim]``."""
        h = self.convs(history.transpose(1, 2))  # Conv1d wants [batch, channels=obs_dim, time=N]
        return self.mlp(h.flatten(1))


def history_to_time_major(x: torch.Tensor, history_length: int, term_dims: tuple[int, ...] | None) -> torch.Tensor:
    """Return the history as ``[batch, N, obs_dim]``, oldest frame first.

    Accepts an mjlab history group either unflattened (``flatten_history_dim=False``: already
    ``[batch, N, obs_dim]``) or flattened, which mjlab lays out term-major
    ``[A_t0 .. A_tN-1, B_t0 .. B_tN-1, ...]``; the flattened form needs the per-term sizes ``term_dims``.
    A single term of size ``obs_dim`` covers a time-major flattened ``[batch, N * obs_dim]`` layout.

    Args:
        x: History group, ``[batch, N, obs_dim]`` or ``[batch, N * obs_dim]``.
        history_length: N.
        term_dims: Per-term frame sizes for the flattened form; ``None`` for the unflattened form.

    Raises:
        ValueError: If the shape does not match the stated layout.
    """
    if x.dim() == 3:
        if x.shape[1] != history_length:
            raise ValueError(f"history group has {x.shape[1]} frames, expected {history_length}.")
        return x
    if term_dims is None:
        raise ValueError("A flattened history group needs `history_term_dims` (mjlab lays it out term-major).")
    if x.shape[-1] != history_length * sum(term_dims):
        raise ValueError(f"history width {x.shape[-1]} != {history_length} * {sum(term_dims)}.")
    chunks = torch.split(x, [history_length * d for d in term_dims], dim=-1)
    return torch.cat([c.reshape(x.shape[0], history_length, d) for c, d in zip(chunks, term_dims, strict=True)], -1)


def flatten_groups(obs: TensorDict, groups: list[str], last_frames: int | None) -> torch.Tensor:
    """Concatenate observation groups into ``[batch, dim]``; 3-D history groups keep their ``last_frames``.

    Args:
        obs: Observation groups.
        groups: Group names, concatenated in this order.
        last_frames: For 3-D groups ``[batch, N, D]``, keep only the newest ``last_frames`` frames (None: all).
    """
    parts = []
    for name in groups:
        x = obs[name]
        if x.dim() == 3:
            x = (x if last_frames is None else x[:, -last_frames:]).flatten(1)
        parts.append(x)
    return torch.cat(parts, dim=-1)
