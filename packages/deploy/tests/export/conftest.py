# SPDX-License-Identifier: Apache-2.0
"""Tiny pure-torch stand-ins for the student policy (deploy does not depend on rsl-rl or gmloco.train)."""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace
from typing import ClassVar

import pytest

torch = pytest.importorskip("torch")
nn = torch.nn

OBS_DIM, HISTORY, LATENT, ACTIONS = 5, 6, 3, 2


class TinyStudentExport(nn.Module):
    """Export contract of ``StudentActor.as_onnx``: ``(obs, history) -> (actions, latent, eta)``."""

    def __init__(self, model: TinyStudent) -> None:
        """Share the policy's modules (the real wrapper deep-copies them)."""
        super().__init__()
        self.encoder, self.mlp, self.decoder = model.encoder, model.mlp, model.decoder

    def forward(self, obs: torch.Tensor, history: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Encode the history, act on [obs, z_hat], decode eta."""
        z = self.encoder(history.transpose(1, 2))
        return self.mlp(torch.cat([obs, z], dim=-1)), z, self.decoder(z)

    def get_dummy_inputs(self) -> tuple[torch.Tensor, torch.Tensor]:
        """Batch-1 zero inputs."""
        return torch.zeros(1, OBS_DIM), torch.zeros(1, HISTORY, OBS_DIM)

    input_names: ClassVar[list[str]] = ["obs", "history"]
    output_names: ClassVar[list[str]] = ["actions", "latent", "eta"]


class TinyStudent(nn.Module):
    """A student-shaped policy: 1-D conv history encoder, MLP actor, decoder, action-noise distribution."""

    def __init__(self) -> None:
        """Build the modules with fixed random weights."""
        super().__init__()
        torch.manual_seed(0)
        self.encoder = nn.Sequential(
            nn.Conv1d(OBS_DIM, 4, 3), nn.ELU(), nn.Flatten(), nn.Linear(4 * (HISTORY - 2), LATENT)
        )
        self.mlp = nn.Sequential(nn.Linear(OBS_DIM + LATENT, 16), nn.ELU(), nn.Linear(16, ACTIONS))
        self.decoder = nn.Sequential(nn.Linear(LATENT, 8), nn.ELU(), nn.Linear(8, 1))
        self.distribution = nn.Module()
        self.distribution.std_param = nn.Parameter(torch.ones(ACTIONS))

    def as_onnx(self, verbose: bool) -> nn.Module:
        """Encoder-aware export wrapper."""
        return TinyStudentExport(self)


class _ObsOnlyExport(nn.Module):
    """What rsl-rl's stock ``MLPModel.as_onnx`` gives: the MLP on ``obs`` only."""

    def __init__(self, model: TinyStudent) -> None:
        """Keep only the MLP."""
        super().__init__()
        self.mlp = model.mlp

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        """Act on obs alone."""
        return self.mlp(obs)

    input_names: ClassVar[list[str]] = ["obs"]
    output_names: ClassVar[list[str]] = ["actions"]


class StockExportStudent(TinyStudent):
    """A policy with an encoder whose as_onnx was not overridden: the encoder would be dropped."""

    def as_onnx(self, verbose: bool) -> nn.Module:
        """Stock-like wrapper without the encoder."""
        return _ObsOnlyExport(self)


class _HistoryIgnoringExport(TinyStudentExport):
    """Takes ``history`` but has no encoder weights (zeros instead of z_hat)."""

    def __init__(self, model: TinyStudent) -> None:
        """Keep the MLP and decoder only."""
        nn.Module.__init__(self)
        self.mlp, self.decoder = model.mlp, model.decoder

    def forward(self, obs: torch.Tensor, history: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Act with a zero latent."""
        z = torch.zeros(obs.shape[0], LATENT) + 0.0 * history.sum()
        return self.mlp(torch.cat([obs, z], dim=-1)), z, self.decoder(z)


class SilentDropStudent(TinyStudent):
    """A policy whose wrapper has the right inputs but leaves the encoder out."""

    def as_onnx(self, verbose: bool) -> nn.Module:
        """Wrapper without encoder weights."""
        return _HistoryIgnoringExport(self)


@pytest.fixture
def dims() -> SimpleNamespace:
    """Sizes of the tiny policy."""
    return SimpleNamespace(obs_dim=OBS_DIM, history=HISTORY, latent=LATENT, actions=ACTIONS)


@pytest.fixture
def students() -> SimpleNamespace:
    """The tiny policy classes: good, stock-export (drops encoder), silent-drop."""
    return SimpleNamespace(good=TinyStudent, stock=StockExportStudent, silent=SilentDropStudent)


@pytest.fixture
def make_metadata() -> Callable[..., object]:
    """Return a factory of metadata matching the tiny policy (two terms: 2 + 3 features)."""
    from gmloco.deploy.export import PolicyMetadata

    def make(**overrides: object) -> PolicyMetadata:
        fields = {
            "joint_names": ["left_knee_joint", "right_knee_joint"],
            "joint_stiffness": [99.1, 99.1],
            "joint_damping": [6.3, 6.3],
            "default_joint_pos": [0.3, 0.3],
            "action_scale": [0.25, 0.5],
            "observation_names": ["command", "joint_pos"],
            "observation_dims": [2, 3],
            "observation_scale": [1.0, [1.0, 1.0, 0.5]],
            "observation_clip": [None, [-100.0, 100.0]],
            "history_length": HISTORY,
            "policy_dt": 0.02,
            "latent_dim": LATENT,
            "commit": "0123abc",
        }
        return PolicyMetadata(**(fields | overrides))  # type: ignore[arg-type]

    return make
