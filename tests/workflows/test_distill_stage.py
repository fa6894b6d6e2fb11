# SPDX-License-Identifier: Apache-2.0
"""The distill stage reads the package's ``DistillCfg`` and ``PpoCfg`` straight from its Hydra section."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from omegaconf import DictConfig

from workflows import distill, train_teacher


def _captured(monkeypatch: pytest.MonkeyPatch, module: Any) -> dict[str, Any]:
    """Replace the stage's ``run_training`` with a recorder of its keyword arguments."""
    seen: dict[str, Any] = {}

    def fake(cfg: DictConfig, name: str, **run_cfg: Any) -> dict[str, float | None]:
        seen.update(run_cfg, stage=name)
        return {}

    monkeypatch.setattr(module, "run_training", fake)
    return seen


def test_every_distill_field_reaches_student_ppo(
    compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """Loss weights, curriculum and PPO settings set at ``distill.<field>`` arrive in StudentPPO's arguments."""
    seen = _captured(monkeypatch, distill)
    checkpoint = tmp_path / "teacher.pt"
    cfg = compose(
        "+exp=gm_loco",
        "distill.w_dist_end=0.2",
        "distill.latent_loss_weight=0.5",
        "distill.ppo.learning_rate=1.0e-4",
        "distill.ppo.schedule=adaptive",
        f"distill.teacher_checkpoint={checkpoint}",
    )
    distill.run(cfg)
    algorithm = seen["rsl_rl_overrides"]["algorithm"]
    assert algorithm["w_dist_end"] == 0.2 and algorithm["latent_loss_weight"] == 0.5
    assert algorithm["learning_rate"] == 1.0e-4 and algorithm["schedule"] == "adaptive"
    assert type(algorithm["schedule"]) is str
    assert seen["init_checkpoint"] == str(checkpoint)


def test_distill_defaults_are_the_package_defaults(compose: Callable[..., DictConfig]) -> None:
    """Without overrides the section holds ``teacher_student.DistillCfg()``'s values (fixed rate 5e-4)."""
    from gmloco.train.teacher_student import DistillCfg

    section = compose("+exp=gm_loco").distill
    default = DistillCfg()
    assert section.ppo.learning_rate == default.ppo.learning_rate == 5.0e-4
    assert section.ppo.schedule == default.ppo.schedule == "fixed"
    assert section.w_dist_end == default.w_dist_end and section.curriculum_finish == default.curriculum_finish


def test_vanilla_ppo_settings_reach_the_algorithm(
    compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every ``PpoCfg`` field, also those GM-Loco leaves at rsl-rl's default, is settable for vanilla PPO."""
    seen = _captured(monkeypatch, train_teacher)
    train_teacher.run(compose("+exp=ppo_rft3d", "train_teacher.ppo.value_loss_coef=0.5", "train_teacher.ppo.lam=0.9"))
    algorithm = seen["rsl_rl_overrides"]["algorithm"]
    assert algorithm["value_loss_coef"] == 0.5 and algorithm["lam"] == 0.9
    assert algorithm["schedule"] == "adaptive" and type(algorithm["optimizer"]) is str


def test_student_fields_reach_the_student_actor(
    compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """``distill.tcn_channels`` and the other ``StudentCfg`` fields arrive in the student actor's cfg."""
    seen = _captured(monkeypatch, distill)
    cfg = compose(
        "+exp=gm_loco",
        "distill.tcn_channels=[16,16,8]",
        "distill.tcn_mlp_hidden_dims=[64]",
        f"distill.teacher_checkpoint={tmp_path / 'teacher.pt'}",
    )
    distill.run(cfg)
    actor = seen["rsl_rl_overrides"]["actor"]
    assert actor["tcn_channels"] == (16, 16, 8) and actor["tcn_mlp_hidden_dims"] == (64,)


def test_student_defaults_follow_the_teacher(compose: Callable[..., DictConfig]) -> None:
    """Without overrides the student is ``StudentCfg()`` with the teacher's actor widths and history length N."""
    from gmloco.train.teacher_student import StudentCfg
    from workflows.section_cfg import section_as

    assert section_as(StudentCfg, compose("+exp=gm_loco").distill) == StudentCfg()
    cfg = compose("+exp=gm_loco", "train_teacher.hidden_dims=[64,32]", "train_teacher.history_length=20")
    student = section_as(StudentCfg, cfg.distill)
    assert student.actor_hidden_dims == (64, 32) and student.history_length == 20
