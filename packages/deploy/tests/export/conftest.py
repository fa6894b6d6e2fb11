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


def tiny_metadata(
    history_length: int = HISTORY,
    layout: str = "frame_and_history",
    history_padding: str = "repeat_first",
    **overrides: object,
) -> object:
    """Metadata of the tiny policy: terms ``command`` (2, clipped) and ``joint_pos`` (3, per-element scale)."""
    from gmloco.deploy.export import metadata as m

    terms = [
        m.ObservationTermSpec("command", 2, 1.0, [-1.0, 1.0], "(v_x [m/s], omega_z [rad/s])"),
        m.ObservationTermSpec("joint_pos", 3, [1.0, 1.0, 0.5], None, "q - q_0 [rad]"),
    ]
    collider = m.FootColliderSpec(
        ["left_foot", "right_foot"], [-0.065, 0.141], [-0.0368, 0.0368], [-0.03539, 0.0], "sole", [5, 5, 5]
    )
    fields = {
        "observation": m.ObservationSpec(terms, history_length, layout, history_padding=history_padding),  # type: ignore[arg-type]
        "joints": m.JointSpec(
            ["left_knee_joint", "right_knee_joint"], [99.1, 99.1], [6.3, 6.3], [0.3, 0.3], [0.25, 0.5], [139.0, 139.0]
        ),
        "timing": m.TimingSpec(physics_dt=0.005, decimation=4, policy_dt=0.02),
        "contact": m.ContactSpec(
            "rft3d", collider, 40.0, {"kind": "flat"}, {"mu_int": [0.2, 0.9]}, {"push_velocity": 1.0}
        ),
        "command": m.CommandSpec("twist", [-1.0, 1.0], [-0.5, 0.5], [-0.5, 0.5], "yaw_target", 1.0),
        "policy_class": "StudentActor",
        "latent_dim": LATENT,
        "commit": "0123abc",
    }
    return m.PolicyMetadata(**(fields | overrides))  # type: ignore[arg-type]


@pytest.fixture
def make_metadata() -> Callable[..., object]:
    """Return :func:`tiny_metadata`, the factory of metadata matching the tiny policy (2 + 3 features)."""
    return tiny_metadata
