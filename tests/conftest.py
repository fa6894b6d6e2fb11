# SPDX-License-Identifier: Apache-2.0
"""Fixtures for the cross-package pipeline tests (the checkout root is on pytest's pythonpath, for ``workflows``)."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from omegaconf import DictConfig


@pytest.fixture(autouse=True)
def _no_wandb(monkeypatch: pytest.MonkeyPatch) -> None:
    """Keep tests off wandb (the tracking config reads ``WANDB_MODE``)."""
    monkeypatch.setenv("WANDB_MODE", "disabled")


@pytest.fixture
def compose() -> Callable[..., DictConfig]:
    """Return ``compose(*overrides)``: the checked pipeline config, as ``@hydra.main`` tasks see it."""
    from workflows.hydra_entry import compose_checked

    def _compose(*overrides: str) -> DictConfig:
        return compose_checked("full_pipeline", list(overrides))

    return _compose
