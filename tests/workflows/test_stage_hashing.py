# SPDX-License-Identifier: Apache-2.0
"""Stage hashes (``workflows/stage_hashing.py``): where a stage runs does not change its record."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from omegaconf import DictConfig

from workflows.stage_hashing import stage_hashes
from workflows.stage_registry import STAGES


@pytest.fixture
def two_gpus(monkeypatch: pytest.MonkeyPatch) -> None:
    """Make the gpus input check see two CUDA devices."""
    import gmloco.train.multi_gpu as multi_gpu

    monkeypatch.setattr(multi_gpu, "cuda_device_count", lambda: 2)


@pytest.mark.usefixtures("two_gpus")
def test_training_gpus_leave_every_stage_hash_unchanged(compose: Callable[..., DictConfig]) -> None:
    """A run resumed on other GPUs keeps its stages: ``train_teacher.gpus`` / ``distill.gpus`` are placement."""
    base = stage_hashes(compose("+exp=gm_loco"), STAGES)
    placed = stage_hashes(compose("+exp=gm_loco", "train_teacher.gpus=[0,1]", "distill.gpus=[1]"), STAGES)
    assert placed == base


@pytest.mark.usefixtures("two_gpus")
def test_training_settings_still_change_the_hash(compose: Callable[..., DictConfig]) -> None:
    """A training setting beside ``gpus`` still changes the train stage's hash and those downstream of it."""
    base = stage_hashes(compose("+exp=gm_loco"), STAGES)
    changed = stage_hashes(compose("+exp=gm_loco", "train_teacher.num_envs=8"), STAGES)
    assert changed["train_teacher"] != base["train_teacher"] and changed["distill"] != base["distill"]
