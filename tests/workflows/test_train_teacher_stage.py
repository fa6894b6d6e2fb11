# SPDX-License-Identifier: Apache-2.0
"""The train_teacher stage hands the VAE teacher's Hydra settings to ``gmloco.train.train`` unchanged."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from omegaconf import DictConfig

import train_teacher


def _captured(monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    """Replace the stage's ``run_training`` with a recorder of its keyword arguments."""
    seen: dict[str, Any] = {}

    def fake(cfg: DictConfig, name: str, **run_cfg: Any) -> dict[str, float | None]:
        seen.update(run_cfg, stage=name)
        return {}

    monkeypatch.setattr(train_teacher, "run_training", fake)
    return seen


def test_warm_start_vae_lr_and_beta_reach_the_run(
    compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``train_teacher.warm_start_ppo`` becomes ``TrainRunCfg.warm_start_ppo``; beta and the VAE rate reach TeacherPPO."""
    seen = _captured(monkeypatch)
    cfg = compose(
        "+exp=gm_loco",
        "train_teacher.warm_start_ppo=artifacts/ppo_rft3d/checkpoint.pt",
        "train_teacher.decoder_learning_rate=0.002",
    )
    train_teacher.run(cfg)
    assert seen["warm_start_ppo"] == "artifacts/ppo_rft3d/checkpoint.pt"
    algorithm = seen["rsl_rl_overrides"]["algorithm"]
    assert algorithm["decoder_learning_rate"] == 0.002 and algorithm["kl_weight"] == 1.0e-4


def test_no_warm_start_by_default(compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch) -> None:
    """Without the override the teacher starts from scratch (no warm_start_ppo passed)."""
    seen = _captured(monkeypatch)
    train_teacher.run(compose("+exp=gm_loco"))
    assert "warm_start_ppo" not in seen
