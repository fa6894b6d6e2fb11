# SPDX-License-Identifier: Apache-2.0
"""The train_teacher stage hands the VAE teacher's Hydra settings to ``gmloco.train.train`` unchanged."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from omegaconf import DictConfig

from workflows import train_teacher


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


@pytest.mark.parametrize(("exp", "contact_model"), [("jump_rft3d", "rft3d"), ("jump_rigid", "rigid")])
def test_jump_exps_train_the_jump_task(
    compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch, exp: str, contact_model: str
) -> None:
    """``+exp=jump_*`` hands a ``JumpTaskCfg`` with its contact model, vanilla PPO settings and no ONNX export."""
    seen = _captured(monkeypatch)
    train_teacher.run(compose(f"+exp={exp}", "train_teacher.jump.assist.scale_step=0.05"))
    jump = seen["jump"]
    assert jump.base.contact_model == contact_model and jump.motion == "vertical"
    assert jump.assist.enabled and jump.assist.initial_scale == 1.0 and jump.assist.scale_step == 0.05
    assert seen["export_onnx"] is False and seen["rsl_rl_overrides"]["algorithm"]["entropy_coef"] == 0.005


def test_jump_section_reaches_every_imitation_field(
    compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The ``jump`` section is the package's JumpImitationCfg: rewards, episode and assist fields reach the task."""
    seen = _captured(monkeypatch)
    overrides = ("train_teacher.jump.motion=forward", "train_teacher.jump.rewards.base_pos_weight=2.5",
                 "train_teacher.jump.max_base_pos_error=0.5", "train_teacher.jump.assist.enabled=false")  # fmt: skip
    train_teacher.run(compose("+exp=jump_rft3d", *overrides))
    jump = seen["jump"]
    assert jump.motion == "forward" and isinstance(jump.motion, str)
    assert jump.rewards.base_pos_weight == 2.5 and jump.max_base_pos_error == 0.5 and not jump.assist.enabled


def test_jump_exps_differ_only_in_the_contact_model(compose: Callable[..., DictConfig]) -> None:
    """PPO-3D-RFT and PPO-Rigid are trained the same way: the two train sections differ in contact_model alone."""
    from omegaconf import OmegaConf

    a = OmegaConf.to_container(compose("+exp=jump_rft3d").train_teacher, resolve=True, enum_to_str=True)
    b = OmegaConf.to_container(compose("+exp=jump_rigid").train_teacher, resolve=True, enum_to_str=True)
    assert isinstance(a, dict) and isinstance(b, dict)
    # out_dir follows the run directory, which is named after the experiment
    assert {k for k in a if a[k] != b[k]} - {"out_dir"} == {"contact_model"}


def test_jump_with_the_vae_teacher_is_refused(compose: Callable[..., DictConfig]) -> None:
    """train_teacher.jump with algorithm=vae_teacher is a composition error naming the key and the fix."""
    from workflows.config_errors import ConfigInputError

    with pytest.raises(ConfigInputError, match="needs algorithm=ppo") as info:
        compose("+exp=jump_rft3d", "train_teacher.algorithm=vae_teacher")
    assert info.value.key == "train_teacher.algorithm"


def test_jump_stage_trains_at_smoke_scale(compose: Callable[..., DictConfig], tmp_path: Any) -> None:
    """``+exp=jump_rigid`` at smoke scale on the CPU trains 2 iterations and writes its checkpoint."""
    cfg = compose(
        "+exp=jump_rigid", "+scale=smoke", "device=cpu", f"run_dir={tmp_path}", "train_teacher.policy_history_length=1"
    )
    metrics = train_teacher.run(cfg)
    assert metrics["iteration"] == 2.0
    assert (tmp_path / "train_teacher" / "model_2.pt").exists()


def test_material_from_the_command_line_reaches_the_task(
    compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``train_teacher.material.<field>`` sets the task's material DR; the VAE teacher still cuts its held-out hole."""
    seen = _captured(monkeypatch)
    train_teacher.run(compose("+exp=ppo_rft3d", "train_teacher.material.mu_int=[0.3,0.6]"))
    assert seen["task"].material.mu_int == (0.3, 0.6) and seen["task"].material.packing == (0.5, 1.0)
    train_teacher.run(compose("+exp=gm_loco", "train_teacher.material.packing=[0.6,1.0]"))
    material = seen["task"].material
    assert material.packing == (0.6, 1.0) and material.held_out_mu_int is not None


def test_material_fields_left_at_default_keep_the_terrains(compose: Callable[..., DictConfig]) -> None:
    """On the deep bed, setting the packing keeps the terrain's own mu_int range (0.1-0.4)."""
    from workflows.policy_training import task_cfg

    section = compose("+exp=ppo_rft3d", "train_teacher.terrain=deep", "train_teacher.material.packing=[0.6,1.0]")
    material = task_cfg(section.train_teacher).material
    assert material.mu_int == (0.1, 0.4) and material.packing == (0.6, 1.0)


def test_gpus_reach_the_run(compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch, tmp_path: Any) -> None:
    """``train_teacher.gpus`` becomes ``TrainRunCfg.gpus``; left empty, the run trains on the pipeline's device."""
    import gmloco.train
    import gmloco.train.multi_gpu as multi_gpu

    monkeypatch.setattr(multi_gpu, "cuda_device_count", lambda: 2)
    seen: list[Any] = []
    monkeypatch.setattr(gmloco.train, "train", lambda cfg, on_iteration=None: seen.append(cfg) or {})
    for gpus in ("[0,1]", "[]"):
        train_teacher.run(compose("+exp=gm_loco", f"run_dir={tmp_path}", f"train_teacher.gpus={gpus}"))
    assert seen[0].gpus == (0, 1) and seen[1].gpus == ()


def test_teacher_section_is_the_package_teacher_cfg(compose: Callable[..., DictConfig]) -> None:
    """Without overrides ``train_teacher`` holds ``TeacherCfg()``, as tuples; ``hidden_dims`` sets both MLPs."""
    from gmloco.train.teacher_student import TeacherCfg
    from workflows.policy_training import teacher_cfg

    assert teacher_cfg(compose("+exp=gm_loco").train_teacher) == TeacherCfg()
    teacher = teacher_cfg(compose("+exp=gm_loco", "train_teacher.hidden_dims=[64,32]").train_teacher)
    assert teacher.actor_hidden_dims == teacher.critic_hidden_dims == (64, 32)
    teacher = teacher_cfg(compose("+exp=gm_loco", "train_teacher.critic_hidden_dims=[256,128]").train_teacher)
    assert teacher.actor_hidden_dims == (512, 256, 128) and teacher.critic_hidden_dims == (256, 128)


def test_every_teacher_field_reaches_the_actor_and_teacher_ppo(
    compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Networks, latent and loss weights set at ``train_teacher.<field>`` arrive in the rsl-rl entries."""
    seen = _captured(monkeypatch)
    cfg = compose(
        "+exp=gm_loco",
        "train_teacher.encoder_hidden_dims=[64,32]",
        "train_teacher.decoder_hidden_dims=[32,64]",
        "train_teacher.latent_dim=8",
        "train_teacher.actor_latent=sample",
        "train_teacher.reconstruction_weight=2.0",
    )
    train_teacher.run(cfg)
    actor, algorithm = seen["rsl_rl_overrides"]["actor"], seen["rsl_rl_overrides"]["algorithm"]
    assert actor["encoder_hidden_dims"] == (64, 32) and actor["decoder_hidden_dims"] == (32, 64)
    assert actor["latent_dim"] == 8 and actor["actor_latent"] == "sample" and type(actor["actor_latent"]) is str
    assert algorithm["reconstruction_weight"] == 2.0


@pytest.mark.parametrize(
    ("override", "key"),
    [
        ("train_teacher.latent_dim=0", "train_teacher.latent_dim"),
        ("train_teacher.kl_weight=-1", "train_teacher.kl_weight"),
    ],
)
def test_teacher_fields_keep_their_ranges(compose: Callable[..., DictConfig], override: str, key: str) -> None:
    """The package's bounds on the teacher's fields are checked at composition, naming the key."""
    from workflows.config_errors import ConfigInputError

    with pytest.raises(ConfigInputError) as info:
        compose("+exp=gm_loco", override)
    assert info.value.key == key
