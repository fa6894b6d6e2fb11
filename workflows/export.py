# SPDX-License-Identifier: Apache-2.0
"""Stage ``export``: ONNX export of the student with deploy metadata, checked with onnxruntime against torch (issue 6).

Loads the newest student checkpoint of ``export.policy_dir`` (the ``distill`` stage) into the student built for the
same task, and writes with ``gmloco.deploy.export``:

* ``policy.onnx``: inputs ``obs`` ``[batch, 96]`` and ``history`` ``[batch, N, 96]``, outputs ``actions``, ``latent``
  and the decoded stiffness ``eta``; the deploy metadata (``gmloco.deploy.export.PolicyMetadata``: observation terms,
  history order, joints with gains and effort limits, timing, contact model and foot collider, materials and
  randomization trained on, command ranges) in its ``metadata_props``, and ``policy.json`` (the same document).
* the parity checks, as metrics: onnxruntime vs torch on random inputs (``export_policy_onnx``), then a rollout of
  ``export.check_steps`` env steps in which ``OnnxPolicyRunner`` keeps its own history and must reproduce the torch
  student's actions and decoded eta on the env's history; every other env times out half-way, so the runner's
  padding after a reset is checked against mjlab's history back-fill. The same rollout gives the student-vs-teacher
  action error and the error of the decoded eta against the true eta
  (:mod:`gmloco.train.teacher_student.export_student`).

Run alone (works with plain ``python`` and ``PYTHONPATH=packages/*/src:workflows``)::

    python workflows/export.py +exp=gm_loco run_dir=runs/gm_loco/<name>

Contract: ``run(cfg)`` reads ``cfg.export`` (and ``cfg.train_teacher`` / ``cfg.distill`` for the networks), writes
every file under ``cfg.export.out_dir`` (``policy.onnx`` via a temporary file and ``os.replace``), and returns the
metrics; it takes seconds, so it has no time box of its own.
"""

from __future__ import annotations

import os
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

from omegaconf import DictConfig

if not __package__:  # run as ``python workflows/<name>.py``: the checkout root makes ``workflows`` importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workflows.policy_training import distill_overrides, newest_checkpoint, task_cfg, torch_device
from workflows.run_dir import atomic_write_json
from workflows.schemas import REPO_ROOT

__all__ = ["main", "run"]

CHECK_NUM_ENVS = 2
"""Envs of the export check rollout."""


def _student_runner(cfg: DictConfig, checkpoint: Path, device: str) -> Any:
    """Build the noise-free task with the ``history`` group and a runner holding the student; load ``checkpoint``."""
    from gmloco.train.teacher_student.export_student import build_runner

    teacher = cfg.train_teacher
    return build_runner(
        replace(task_cfg(teacher), play=True),
        distill_overrides(cfg),
        int(teacher.history_length),
        checkpoint,
        device,
        num_envs=CHECK_NUM_ENVS,
        seed=int(cfg.seed),
        hidden_dims=tuple(int(d) for d in teacher.hidden_dims),
    )


def _metadata(runner: Any, cfg: DictConfig, checkpoint: Path) -> Any:
    """Deploy metadata of the student from the live env (mjlab's base metadata + history, dt, latent, commit)."""
    from gmloco.deploy.logs import git_commit
    from gmloco.train.teacher_student.export_student import student_policy_metadata

    run_path = os.path.relpath(checkpoint, cfg.run_dir)
    history, latent = int(cfg.train_teacher.history_length), int(cfg.train_teacher.latent_dim)
    return student_policy_metadata(
        runner, task_cfg(cfg.train_teacher), history, latent, run_path, git_commit(REPO_ROOT)[0]
    )


def run(cfg: DictConfig) -> dict[str, float]:
    """Export the newest student checkpoint to ONNX with deploy metadata and check it; return the metrics."""
    section = cfg.export
    out = Path(section.out_dir)
    checkpoint = newest_checkpoint(section.policy_dir)
    runner = _student_runner(cfg, checkpoint, torch_device(str(cfg.device)))
    try:
        from gmloco.train.teacher_student.export_student import export_student_onnx, rollout_parity_check

        metadata = _metadata(runner, cfg, checkpoint)
        atol, steps = float(section.parity_atol), int(section.check_steps)
        path, random_err = export_student_onnx(runner, out / "policy.onnx", metadata, atol)
        atomic_write_json(out / "policy.json", metadata.to_dict())
        checks = rollout_parity_check(runner, path, steps, atol, force_reset_after=max(steps // 2, 1))
    finally:
        runner.env.close()
    size = path.stat().st_size
    return {"onnx_max_abs_diff": random_err, **checks, "onnx_bytes": float(size), "obs_dim": float(metadata.obs_dim)}


def main() -> None:
    """Command-line entry: run this stage alone in a run directory (Hydra)."""
    from workflows.hydra_entry import hydra_entry
    from workflows.pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra, only_stage="export")


if __name__ == "__main__":
    main()
