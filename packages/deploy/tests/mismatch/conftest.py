# SPDX-License-Identifier: Apache-2.0
"""Shared tiny recordings for the mismatch tests (generated once per session, 3 s, noise on)."""

from __future__ import annotations

import pytest

from gmloco.deploy.mismatch.benchmark.controller import MotionCfg
from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
from gmloco.deploy.mismatch.benchmark.truth import TruthEffect


def make(effect: TruthEffect, duration: float = 3.0, kind: str = "step", seed: int = 3) -> object:
    """Generate a short benchmark recording."""
    rec, _ = generate(
        EpisodeCfg(effect=effect, duration=duration, seed=seed, motion=MotionCfg(kind=kind, stand_time=0.3))
    )
    return rec


@pytest.fixture(scope="session")
def null_rec() -> object:
    """A 3 s stepping recording with no hidden effect (nuisances and noise on)."""
    return make(TruthEffect())


@pytest.fixture(scope="session")
def delay_rec() -> object:
    """A 3 s stepping recording with a hidden 12 ms command delay."""
    return make(TruthEffect("actuator.delay", {"delay": [0.012]}))
