# SPDX-License-Identifier: Apache-2.0
"""Bridge from the training stages' Hydra sections to ``gmloco.train`` (no Hydra here beyond reading a DictConfig).

``train_teacher`` and ``distill`` both run :func:`gmloco.train.train` (time-boxed, resumable, atomic checkpoints);
they differ only in the rsl-rl entries merged over the PPO runner cfg (``TrainRunCfg.rsl_rl_overrides``), in the
env's ``history`` group and, for distillation, in the teacher checkpoint loaded first. ``export`` rebuilds the
same student from these helpers.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf

from workflows.pipeline_report import say, stage_bar
from workflows.section_cfg import field_values, section_as
from workflows.stage_registry import StageIncompleteError
from workflows.task_fields import apply_task_fields, flat_paths

__all__ = [
    "distill_overrides",
    "jump_task_cfg",
    "material_cfg",
    "newest_checkpoint",
    "ppo_cfg",
    "run_training",
    "task_cfg",
    "teacher_cfg",
    "teacher_checkpoint",
    "torch_device",
    "vanilla_ppo_overrides",
]

_CHECKPOINT = re.compile(r"^model_(\d+)\.pt$")
"""Checkpoint names written by ``gmloco.train``'s runner."""
_RUN_STATE = ("train_cfg.json", "metrics.json")
"""Files besides checkpoints that tie a training folder to one config."""


def torch_device(device: str) -> str:
    """Map the pipeline's resolved device (``cpu``, ``cuda``, ``cuda:N``) to a torch / Warp device string."""
    return "cuda:0" if device == "cuda" else device


def newest_checkpoint(folder: str | Path) -> Path:
    """Return the ``model_<it>.pt`` with the highest iteration in ``folder``.

    Raises:
        FileNotFoundError: If there is none.
    """
    found = [(int(m.group(1)), p) for p in Path(folder).glob("model_*.pt") if (m := _CHECKPOINT.match(p.name))]
    if not found:
        raise FileNotFoundError(f"no model_<iteration>.pt checkpoint in {folder}")
    return max(found)[1]


def task_cfg(section: DictConfig) -> Any:
    """Return the ``GranularTaskCfg`` of a train section: contact model x terrain (x material), stacked actor frames.

    The fields ``section.task`` names are then set by their paths (:func:`workflows.task_fields.apply_task_fields`).
    """
    from gmloco.train import g1_granular_task

    task = g1_granular_task(str(section.contact_model.value), str(section.terrain.value))  # type: ignore[arg-type]
    if section.get("material") is not None:
        task = replace(task, material=material_cfg(section.material, task.material))
    clearance = section.get("foot_clearance", "penalty")
    if str(getattr(section.get("algorithm", ""), "value", "")) == "vae_teacher":
        from gmloco.train.teacher_student.heldout import with_held_out

        task = with_held_out(task)  # the materials eval_ts scores as never seen in training
    task = replace(
        task,
        policy_history_length=int(section.policy_history_length),
        curriculum_scale=float(section.get("curriculum_scale", 1.0)),
        foot_clearance=str(getattr(clearance, "value", clearance)),  # type: ignore[arg-type]
    )
    return apply_task_fields(task, flat_paths(section.get("task") or {}))


def material_cfg(node: DictConfig, terrain_material: Any) -> Any:
    """Return ``terrain_material`` (a ``MaterialRangeCfg``) with the fields a ``train_teacher.material`` node sets.

    A field the node leaves at ``MaterialRangeCfg``'s default keeps the terrain's value (the deep bed's mu_int).
    """
    from gmloco.train.config import MaterialRangeCfg

    values = OmegaConf.to_container(node, resolve=True)
    assert isinstance(values, dict)
    default = MaterialRangeCfg()
    as_set = {str(k): tuple(v) if isinstance(v, list) else v for k, v in values.items()}
    return replace(terrain_material, **{k: v for k, v in as_set.items() if v != getattr(default, k)})


def jump_task_cfg(section: DictConfig) -> Any:
    """Return the ``JumpTaskCfg`` of a train section whose ``jump`` node is set (contact model, imitation fields)."""
    from gmloco.train.tasks.g1_jump.config import JumpImitationCfg, g1_jump_task

    imitation = section_as(JumpImitationCfg, section.jump)
    motion = str(section.jump.motion.value)
    task = g1_jump_task(str(section.contact_model.value), motion)  # type: ignore[arg-type]
    base = replace(task.base, policy_history_length=int(section.policy_history_length))
    return replace(task, **(field_values(imitation) | {"motion": motion, "base": base}))


def ppo_cfg(section: DictConfig) -> Any:
    """Return the ``teacher_student.PpoCfg`` a section's ``ppo`` node holds (its structured config)."""
    from gmloco.train.teacher_student import PpoCfg

    ppo = OmegaConf.to_object(section.ppo)
    assert isinstance(ppo, PpoCfg)
    return ppo


def vanilla_ppo_overrides(section: DictConfig) -> dict[str, Any]:
    """Return the ``algorithm`` entry of GM-Loco's PPO runner cfg with the section's PPO settings."""
    from dataclasses import asdict

    from gmloco.train import make_g1_granular_ppo_cfg

    algorithm = asdict(make_g1_granular_ppo_cfg().algorithm)
    return {"algorithm": algorithm | ppo_cfg(section).to_rsl_rl()}


def teacher_cfg(section: DictConfig) -> Any:
    """Return the ``TeacherCfg`` of the ``train_teacher`` section (VAE teacher; the section extends it)."""
    from gmloco.train.teacher_student import TeacherCfg

    return section_as(TeacherCfg, section)


def distill_overrides(cfg: DictConfig) -> dict[str, Any]:
    """Return the student's rsl-rl entries (actor, critic, frozen teacher, StudentPPO, obs groups).

    The ``distill`` section is a ``teacher_student.DistillCfg`` and a ``StudentCfg`` (its schema extends both
    package dataclasses), so its loss weights, curriculum, PPO settings and TCN reach ``student_train_entries`` as
    composed.
    """
    from gmloco.train.teacher_student import DistillCfg, StudentCfg, student_train_entries

    teacher = teacher_cfg(cfg.train_teacher)
    student = section_as(StudentCfg, cfg.distill)
    distill = section_as(DistillCfg, cfg.distill)
    return student_train_entries(teacher, student, distill)


def teacher_checkpoint(section: DictConfig) -> Path:
    """Return the teacher checkpoint a ``distill`` section names, else the newest one of its ``teacher_dir``."""
    if section.teacher_checkpoint is not None:
        return Path(section.teacher_checkpoint)
    return newest_checkpoint(section.teacher_dir)


def _start_fresh(run_dir: Path) -> None:
    """Delete the checkpoints and run files of an earlier config (the stage was forced or its config changed)."""
    for p in [*run_dir.glob("model_*.pt"), *(run_dir / name for name in _RUN_STATE)]:
        p.unlink(missing_ok=True)


def _announce_resume(name: str, folder: Path) -> None:
    """Say which checkpoint a stage continues from, when its folder holds one (``train`` resumes from it)."""
    found = [(int(m.group(1)), p) for p in folder.glob("model_*.pt") if (m := _CHECKPOINT.match(p.name))]
    if found:
        iteration, path = max(found)
        say(f"  {name}: resumed from {path} (iteration {iteration})")


def run_training(cfg: DictConfig, name: str, **run_cfg: Any) -> dict[str, float | None]:
    """Run ``gmloco.train.train`` for stage ``name``; raise ``StageIncompleteError`` when its time box stopped it.

    Args:
        cfg: The pipeline config (the stage's section is ``cfg[name]``).
        name: ``train_teacher`` or ``distill``.
        **run_cfg: ``TrainRunCfg`` fields that depend on the stage (task, overrides, history, ...).

    Returns:
        ``train``'s metrics, with non-finite values as None.
    """
    from gmloco.train import TrainRunCfg, train

    section = cfg[name]
    out = Path(section.out_dir)
    if not section.resume:
        _start_fresh(out)
    _announce_resume(name, out)
    total = int(section.max_iterations)
    with stage_bar(f"{name} iterations", total, "iterations") as update:
        metrics = train(
            TrainRunCfg(
                num_envs=int(section.num_envs),
                max_iterations=total,
                max_minutes=None if section.max_minutes is None else float(section.max_minutes),
                seed=int(cfg.seed),
                device=torch_device(str(cfg.device)),
                run_dir=str(out),
                save_interval=int(section.save_interval),
                num_steps_per_env=int(section.num_steps_per_env),
                gpus=tuple(int(g) for g in section.get("gpus", [])),
                **run_cfg,
            ),
            on_iteration=lambda done, _total: update(done),
        )
    if metrics.get("stopped_by_deadline"):
        it, total = int(metrics["iteration"]), int(section.max_iterations)
        raise StageIncompleteError(f"time box reached at iteration {it} of {total}; checkpoint model_{it}.pt saved")
    return {k: (float(v) if math.isfinite(v) else None) for k, v in metrics.items()}
