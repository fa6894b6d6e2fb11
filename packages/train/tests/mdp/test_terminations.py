# SPDX-License-Identifier: Apache-2.0
"""``physics_diverged``: non-finite or impossibly fast worlds end, moving ones do not."""

from __future__ import annotations

from types import SimpleNamespace

import torch

from gmloco.train.mdp import physics_diverged
from gmloco.train.mdp.terminations import MAX_PHYSICAL_SPEED


def _env(qvel: torch.Tensor) -> SimpleNamespace:
    """A stand-in env with the physics arrays ``physics_diverged`` reads: 4 worlds, 36 qpos, 35 qvel."""
    worlds = qvel.shape[0]
    data = SimpleNamespace(
        qpos=torch.zeros(worlds, 36),
        qvel=qvel,
        qacc=torch.zeros(worlds, 35),
        qacc_warmstart=torch.zeros(worlds, 35),
        sensordata=torch.zeros(worlds, 4),
    )
    return SimpleNamespace(sim=SimpleNamespace(data=data))


def test_physics_diverged_flags_nan_inf_and_runaway_speed_only() -> None:
    """NaN, inf and a speed past the bound end a world; a hard fall just under it does not."""
    qvel = torch.full((5, 35), 30.0)  # a hard fall: every joint near its limit
    qvel[1, 3] = float("nan")
    qvel[2, 0] = float("-inf")
    qvel[3, 20] = -1.01 * MAX_PHYSICAL_SPEED
    qvel[4, 20] = 0.99 * MAX_PHYSICAL_SPEED
    assert physics_diverged(_env(qvel)).tolist() == [False, True, True, True, False]  # type: ignore[arg-type]


def test_physics_diverged_threshold_is_a_parameter() -> None:
    """A lower bound ends worlds the default keeps."""
    qvel = torch.full((2, 35), 30.0)
    assert physics_diverged(_env(qvel), max_speed=20.0).tolist() == [True, True]  # type: ignore[arg-type]
