# SPDX-License-Identifier: Apache-2.0
"""Stage ``train_teacher``: the train stage: vanilla PPO or the GM-Loco VAE teacher on the granular G1 (issues 4, 6).

``train_teacher.algorithm`` picks what is trained, both through the time-boxed, resumable ``gmloco.train.train``:

* ``ppo`` (``+exp=ppo_rft3d|ppo_heuristic_rft|ppo_cone_multi|ppo_rigid``): vanilla PPO with that contact model;
  writes ``model_<it>.pt``, TensorBoard events and ``policy.onnx`` (+ ``policy.json``, mjlab deploy metadata).
* ``ppo`` with ``train_teacher.jump`` set (``+exp=jump_rft3d|jump_rigid``): the jump imitation task of
  ``gmloco.train.tasks.g1_jump`` (tracking rewards, phase observation, assistive base wrench annealed by a
  curriculum); writes ``model_<it>.pt`` and TensorBoard events (the assist state travels in the checkpoints).
* ``vae_teacher`` (``+exp=gm_loco``): ``TeacherPPO`` with the ``TeacherActor`` (VAE terrain encoder over the critic
  group and the ``history`` group, eta decoder) and the asymmetric MLP critic; writes ``model_<it>.pt`` (the
  ``distill`` stage reads the newest one) and TensorBoard events.

Run alone (time-boxed and resumable; works with plain ``python`` and ``PYTHONPATH=packages/*/src:workflows``)::

    python workflows/train_teacher.py +exp=gm_loco run_dir=runs/gm_loco/<name> max_minutes=9
    python workflows/train.py +exp=ppo_rft3d run_dir=runs/ppo_rft3d/<name> max_minutes=9

Contract: ``run(cfg)`` reads ``cfg.train_teacher`` (plus ``cfg.seed`` and the resolved ``cfg.device``), writes every
file under ``cfg.train_teacher.out_dir`` (checkpoints atomically), stops by ``cfg.train_teacher.max_minutes``
with a checkpoint and raises ``StageIncompleteError`` (rerun to continue from it), and returns ``train``'s metrics.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from omegaconf import DictConfig

if not __package__:  # run as ``python workflows/<name>.py``: the checkout root makes ``workflows`` importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workflows.policy_training import jump_task_cfg, run_training, task_cfg, teacher_cfg, vanilla_ppo_overrides

__all__ = ["main", "run"]


def run(cfg: DictConfig, task: Any = None) -> dict[str, float | None]:
    """Train (or resume) the stage's policy and return its metrics.

    ``task``: the velocity task (``GranularTaskCfg``) to train instead of the section's, e.g. a sweep trial's.
    """
    section = cfg.train_teacher
    task = task_cfg(section) if task is None else task
    run_cfg: dict[str, Any] = {"task": task, "hidden_dims": tuple(int(d) for d in section.hidden_dims)}
    if section.get("jump") is not None:
        if section.algorithm.value != "ppo":
            raise ValueError(
                f"train_teacher.jump needs train_teacher.algorithm=ppo, got {section.algorithm.value}; "
                "the jump imitation task trains vanilla PPO (+exp=jump_rft3d or +exp=jump_rigid)"
            )
        # The jump policy has no deploy metadata yet, so no ONNX export here.
        run_cfg |= {"jump": jump_task_cfg(section), "rsl_rl_overrides": vanilla_ppo_overrides(section)}
        return run_training(cfg, "train_teacher", **run_cfg, export_onnx=False)
    if section.algorithm.value == "ppo":
        run_cfg |= {"rsl_rl_overrides": vanilla_ppo_overrides(section), "export_onnx": True}
    else:
        from gmloco.train.teacher_student import ObsGroupsCfg

        overrides = teacher_cfg(section).to_rsl_rl(ObsGroupsCfg())
        # The teacher is not deployed (the exported policy is the student), so no ONNX export here.
        run_cfg |= {"rsl_rl_overrides": overrides, "history_length": int(section.history_length), "export_onnx": False}
        if section.warm_start_ppo is not None:
            run_cfg["warm_start_ppo"] = str(section.warm_start_ppo)
    return run_training(cfg, "train_teacher", **run_cfg)


def main() -> None:
    """Command-line entry: run this stage alone in a run directory (Hydra)."""
    from workflows.hydra_entry import hydra_entry
    from workflows.pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra, only_stage="train_teacher")


if __name__ == "__main__":
    main()
