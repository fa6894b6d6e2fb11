# SPDX-License-Identifier: Apache-2.0
"""Stage ``distill``: TCN student distilled from the frozen VAE teacher with DAgger + PPO (issue 6).

Reads ``distill.teacher_checkpoint`` or else the newest ``model_<it>.pt`` of ``distill.teacher_dir`` (the
``train_teacher`` stage), builds the same task with the ``history`` observation group, and runs ``StudentPPO``
(student acts, frozen teacher labels; w_PPO / w_dist curriculum) through the time-boxed, resumable
``gmloco.train.train``. The teacher is loaded through ``StudentPPO.load``; later checkpoints carry it
(``teacher_state_dict``), so a resumed run needs no teacher path.

Run alone (time-boxed and resumable; works with plain ``python`` and ``PYTHONPATH=packages/*/src:workflows``)::

    python workflows/distill.py +exp=gm_loco run_dir=runs/gm_loco/<name> max_minutes=9

Contract: ``run(cfg)`` reads ``cfg.distill`` and ``cfg.train_teacher`` (the teacher's task and networks, plus
``cfg.seed`` and the resolved ``cfg.device``), writes every file under ``cfg.distill.out_dir`` (checkpoints
atomically), stops by ``cfg.distill.max_minutes`` with a checkpoint and raises ``StageIncompleteError``, and returns
``train``'s metrics.
"""

from __future__ import annotations

import sys
from pathlib import Path

from omegaconf import DictConfig

if not __package__:  # run as ``python workflows/<name>.py``: the checkout root makes ``workflows`` importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workflows.policy_training import distill_overrides, run_training, task_cfg, teacher_checkpoint

__all__ = ["main", "run"]


def run(cfg: DictConfig) -> dict[str, float | None]:
    """Distil (or resume distilling) the student from the teacher checkpoint; return the training metrics."""
    teacher = cfg.train_teacher
    if teacher.algorithm.value != "vae_teacher":
        raise ValueError(
            f"distill needs the VAE teacher (train_teacher.algorithm=vae_teacher), got {teacher.algorithm.value}"
        )
    return run_training(
        cfg,
        "distill",
        task=task_cfg(teacher),
        hidden_dims=tuple(int(d) for d in teacher.hidden_dims),
        rsl_rl_overrides=distill_overrides(cfg),
        history_length=int(teacher.history_length),
        init_checkpoint=str(teacher_checkpoint(cfg.distill)),
        export_onnx=False,
    )


def main() -> None:
    """Command-line entry: run this stage alone in a run directory (Hydra)."""
    from workflows.hydra_entry import hydra_entry
    from workflows.pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra, only_stage="distill")


if __name__ == "__main__":
    main()
