# SPDX-License-Identifier: Apache-2.0
"""Stage ``export``: ONNX export of the student with deploy metadata, checked with onnxruntime against torch (issue 6).

Loads the newest student checkpoint of ``export.policy_dir`` (the ``distill`` stage) into the student built for the
same task, and writes with ``gmloco.deploy.export``:

* ``policy.onnx``: inputs ``obs`` ``[batch, 96]`` and ``history`` ``[batch, N, 96]``, outputs ``actions``, ``latent``
  and the decoded stiffness ``eta``; the deploy metadata (joints, kp/kd, default pose, action scale, observation
  layout and scaling, history length, policy dt, commit) in its ``metadata_props``, and ``policy.json`` (the same).
* the parity checks, as metrics: onnxruntime vs torch on random inputs (``export_policy_onnx``), then a rollout of
  ``export.check_steps`` env steps in which ``OnnxPolicyRunner`` keeps its own history and must reproduce the torch
  student on the env's history; the same rollout gives the student-vs-teacher action error and the error of the
  decoded eta against the true eta.

Run alone (works with plain ``python`` and ``PYTHONPATH=packages/*/src:workflows``)::

    python workflows/export.py +exp=gm_loco run_dir=runs/gm_loco/<name>

Contract: ``run(cfg)`` reads ``cfg.export`` (and ``cfg.train_teacher`` / ``cfg.distill`` for the networks), writes
every file under ``cfg.export.out_dir`` (``policy.onnx`` via a temporary file and ``os.replace``), and returns the
metrics; it takes seconds, so it has no time box of its own.
"""

from __future__ import annotations

import math
import os
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from omegaconf import DictConfig

from policy_training import distill_overrides, newest_checkpoint, task_cfg, torch_device
from run_dir import atomic_write_json
from schemas import REPO_ROOT

__all__ = ["main", "run"]

CHECK_NUM_ENVS = 2
"""Envs of the export check rollout."""


def _student_runner(cfg: DictConfig, checkpoint: Path, device: str) -> Any:
    """Build the noise-free task with the ``history`` group and a runner holding the student; load ``checkpoint``."""
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.rl import RslRlVecEnvWrapper

    from gmloco.train import make_g1_granular_env_cfg, make_g1_granular_ppo_cfg
    from gmloco.train.rl.runner import GmlocoOnPolicyRunner

    teacher = cfg.train_teacher
    task = replace(task_cfg(teacher), play=True)
    env_cfg = make_g1_granular_env_cfg(task, CHECK_NUM_ENVS, int(teacher.history_length))
    env_cfg.seed = int(cfg.seed)
    env = RslRlVecEnvWrapper(ManagerBasedRlEnv(cfg=env_cfg, device=device))
    train_cfg = asdict(make_g1_granular_ppo_cfg(hidden_dims=tuple(int(d) for d in teacher.hidden_dims)))
    runner = GmlocoOnPolicyRunner(env, train_cfg | distill_overrides(cfg), None, device)
    runner.load(str(checkpoint))
    return runner


def _metadata(runner: Any, cfg: DictConfig, checkpoint: Path) -> Any:
    """Deploy metadata of the student from the live env (mjlab's base metadata + history, dt, latent, commit)."""
    from mjlab.rl.exporter_utils import get_base_metadata

    from gmloco.deploy.export import PolicyMetadata
    from gmloco.deploy.logs import git_commit
    from gmloco.train.teacher_student import policy_metadata_kwargs

    env = runner.env.unwrapped
    dims = [math.prod(d) for d in env.observation_manager.group_obs_term_dim["actor"]]
    run_path = os.path.relpath(checkpoint, cfg.run_dir)
    kwargs = policy_metadata_kwargs(
        get_base_metadata(env, run_path),
        observation_dims=dims,
        history_length=int(cfg.train_teacher.history_length),
        policy_dt=float(env.step_dt),
        latent_dim=int(cfg.train_teacher.latent_dim),
        commit=git_commit(REPO_ROOT)[0],
    )
    return PolicyMetadata(**kwargs)


def _export(runner: Any, metadata: Any, out: Path, atol: float) -> tuple[Path, float]:
    """Export the student to ``out/policy.onnx`` atomically; return the path and the random-input parity error."""
    from gmloco.deploy.export import export_policy_onnx, verify_parity

    policy = runner.alg.get_policy()
    tmp = out / "policy.onnx.tmp"
    export_policy_onnx(policy, tmp, metadata, verify=False)
    err = verify_parity(policy.as_onnx(verbose=False).to("cpu").eval(), tmp, atol=atol)
    path = out / "policy.onnx"
    os.replace(tmp, path)
    return path, err


def _rollout_check(runner: Any, path: Path, steps: int, atol: float) -> dict[str, float]:
    """Step the env with the torch student while ``OnnxPolicyRunner`` keeps its own history; compare them.

    Raises:
        ParityError: If onnxruntime's action differs from torch's by more than ``atol``.
    """
    import numpy as np
    import torch

    from gmloco.deploy.export import OnnxPolicyRunner, ParityError

    env, student, teacher = runner.env, runner.get_inference_policy(), runner.alg.teacher
    onnx_runner = OnnxPolicyRunner(path, num_envs=env.num_envs)
    obs = env.get_observations()
    parity, action_err, eta_err = 0.0, [], []
    for _ in range(steps):
        with torch.no_grad():
            actions, teacher_actions = student(obs), teacher(obs)
        onnx_actions = onnx_runner.step(obs["actor"].cpu().numpy())
        parity = max(parity, float(np.max(np.abs(onnx_actions - actions.cpu().numpy()))))
        action_err.append(float(torch.mean((actions - teacher_actions) ** 2)))
        eta_err.append(float(np.mean(np.abs(onnx_runner.eta[:, 0] - obs["critic"][:, -1].cpu().numpy()))))  # type: ignore[index]
        obs, _, dones, _ = env.step(actions)
        onnx_runner.reset(np.flatnonzero(dones.cpu().numpy()))
    if parity > atol:
        raise ParityError(f"OnnxPolicyRunner vs torch student on env observations: {parity:.3g} > {atol:.1g}")
    return {
        "rollout_onnx_max_abs_diff": parity,
        "student_teacher_action_mse": float(np.mean(action_err)),
        "decoded_eta_mae": float(np.mean(eta_err)),
    }


def run(cfg: DictConfig) -> dict[str, float]:
    """Export the newest student checkpoint to ONNX with deploy metadata and check it; return the metrics."""
    section = cfg.export
    out = Path(section.out_dir)
    checkpoint = newest_checkpoint(section.policy_dir)
    runner = _student_runner(cfg, checkpoint, torch_device(str(cfg.device)))
    try:
        metadata = _metadata(runner, cfg, checkpoint)
        path, random_err = _export(runner, metadata, out, float(section.parity_atol))
        atomic_write_json(out / "policy.json", asdict(metadata))
        checks = _rollout_check(runner, path, int(section.check_steps), float(section.parity_atol))
    finally:
        runner.env.close()
    size = path.stat().st_size
    return {"onnx_max_abs_diff": random_err, **checks, "onnx_bytes": float(size), "obs_dim": float(metadata.obs_dim)}


def main() -> None:
    """Command-line entry: run this stage alone in a run directory (Hydra)."""
    from hydra_entry import hydra_entry
    from pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra, only_stage="export")


if __name__ == "__main__":
    main()
