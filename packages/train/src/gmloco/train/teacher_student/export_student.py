# SPDX-License-Identifier: Apache-2.0
"""Rebuild a trained student on the granular G1 env, export it to ONNX with deploy metadata, check it in a rollout.

Used by the ``export`` pipeline stage and by ``scripts/gpu/train_ts_chunk.py``. The exported file is the deployed
policy: inputs ``obs`` ``[batch, 96]`` and ``history`` ``[batch, N, 96]``; outputs ``actions``, ``latent`` and the
decoded stiffness ``eta`` (:mod:`gmloco.deploy.export`). The rollout check steps the env with the torch student while
:class:`~gmloco.deploy.export.OnnxPolicyRunner` keeps its own history (episodes shortened so that resets happen and
the runner's reset padding is exercised against mjlab's history back-fill).

mjlab and the env stack are imported inside the functions.
"""

from __future__ import annotations

import os
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch

from gmloco.deploy.export import OnnxPolicyRunner, ParityError, export_policy_onnx, verify_parity
from gmloco.train.config import GranularTaskCfg

__all__ = ["build_runner", "export_student_onnx", "rollout_parity_check", "student_policy_metadata"]


def build_runner(
    task: GranularTaskCfg,
    rsl_rl_overrides: dict[str, Any],
    history_length: int,
    checkpoint: str | Path | None,
    device: str,
    num_envs: int = 2,
    seed: int = 0,
    hidden_dims: tuple[int, ...] = (512, 256, 128),
    episode_length_s: float | None = None,
) -> Any:
    """Build the env with the ``history`` group and a ``GmlocoOnPolicyRunner`` for the given rsl-rl entries.

    Args:
        task: Task config (``play=True`` for evaluation: no noise, no pushes, no curricula).
        rsl_rl_overrides: Entries merged over GM-Loco's PPO runner cfg (``TeacherCfg.to_rsl_rl`` or the student's).
        history_length: N of the ``history`` group.
        checkpoint: Checkpoint loaded into the runner (None: fresh weights).
        device: Torch / Warp device.
        num_envs: Number of envs.
        seed: Env seed.
        hidden_dims: Actor / critic widths of the base PPO cfg (replaced by the overrides' models).
        episode_length_s: Override of the episode length [s] (e.g. short, to force resets).
    """
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.rl import RslRlVecEnvWrapper

    from gmloco.train.rl.runner import GmlocoOnPolicyRunner
    from gmloco.train.tasks.g1_granular import make_g1_granular_env_cfg, make_g1_granular_ppo_cfg

    if episode_length_s is not None:
        task = replace(task, episode_length_s=episode_length_s)
    env_cfg = make_g1_granular_env_cfg(task, num_envs, history_length)
    env_cfg.seed = seed
    env = RslRlVecEnvWrapper(ManagerBasedRlEnv(cfg=env_cfg, device=device))
    train_cfg = asdict(make_g1_granular_ppo_cfg(hidden_dims=hidden_dims)) | rsl_rl_overrides
    runner = GmlocoOnPolicyRunner(env, train_cfg, None, device)
    if checkpoint is not None:
        runner.load(str(checkpoint))
    return runner


def student_policy_metadata(
    runner: Any, task: GranularTaskCfg, history_length: int, latent_dim: int, run_path: str, commit: str
) -> Any:
    """Return the student's ``PolicyMetadata``: joints and term widths from the live env, the rest from ``task``.

    Args:
        runner: Runner on an env built for (a play-mode variant of) ``task``.
        task: The training task (its terrain, materials and randomization are recorded as trained on).
        history_length: N of the student's ``history`` input.
        latent_dim: Student latent size.
        run_path: Training run identifier.
        commit: Git commit of the training code.
    """
    from gmloco.train.tasks.g1_granular.policy_metadata import policy_metadata_from_env

    return policy_metadata_from_env(
        runner.env.unwrapped, task, layout="frame_and_history", history_length=history_length,
        policy_class="StudentActor", latent_dim=latent_dim, run_path=run_path, commit=commit,
    )  # fmt: skip


def export_student_onnx(runner: Any, path: str | Path, metadata: Any, atol: float = 1e-5) -> tuple[Path, float]:
    """Export the runner's student to ``path`` atomically (tmp + ``os.replace``); return it and the parity error.

    Raises:
        ParityError: If onnxruntime and torch differ by more than ``atol`` on random inputs.
    """
    path = Path(path)
    policy = runner.alg.get_policy()
    tmp = path.with_suffix(".onnx.tmp")
    export_policy_onnx(policy, tmp, metadata, verify=False)
    err = verify_parity(policy.as_onnx(verbose=False).to("cpu").eval(), tmp, atol=atol)
    os.replace(tmp, path)
    return path, err


def rollout_parity_check(
    runner: Any, path: str | Path, steps: int, atol: float = 1e-5, force_reset_after: int | None = None
) -> dict[str, float]:
    """Step the env with the torch student while ``OnnxPolicyRunner`` keeps its own history; compare them.

    Args:
        runner: Runner holding the student (``StudentPPO``) on an env with the ``history`` group.
        path: Exported student ONNX file.
        steps: Env steps of the check.
        atol: Largest accepted onnxruntime-vs-torch difference.
        force_reset_after: If set, every other env times out after this many steps (its episode counter is moved
            forward), so the runner's padding after a reset is compared with mjlab's history back-fill.

    Returns:
        ``rollout_onnx_max_abs_diff`` (actions, onnxruntime vs torch), ``rollout_eta_max_abs_diff`` (decoded eta),
        ``student_teacher_action_mse``, ``decoded_eta_mae`` (student's psi(z_hat) vs the true eta) and
        ``rollout_resets`` (env resets seen, whose history padding was checked).

    Raises:
        ParityError: If onnxruntime's action or eta differs from torch's by more than ``atol``.
    """
    env, student, teacher = runner.env, runner.get_inference_policy(), runner.alg.teacher
    onnx_runner = OnnxPolicyRunner(path, num_envs=env.num_envs)
    if force_reset_after is not None:
        env.episode_length_buf[::2] = int(env.max_episode_length) - force_reset_after
    obs = env.get_observations()
    act_diff, eta_diff, resets, action_err, eta_err = 0.0, 0.0, 0, [], []
    for _ in range(steps):
        with torch.no_grad():
            actions, teacher_actions = student(obs), teacher(obs)
            eta_hat = runner.alg.actor.decode(runner.alg.actor.latent)
        onnx_actions = onnx_runner.step(obs["actor"].cpu().numpy())
        assert onnx_runner.eta is not None
        act_diff = max(act_diff, float(np.max(np.abs(onnx_actions - actions.cpu().numpy()))))
        eta_diff = max(eta_diff, float(np.max(np.abs(onnx_runner.eta - eta_hat.cpu().numpy()))))
        action_err.append(float(torch.mean((actions - teacher_actions) ** 2)))
        eta_err.append(float(torch.mean(torch.abs(eta_hat[:, 0] - obs["critic"][:, -1]))))
        obs, _, dones, _ = env.step(actions)
        done_ids = np.flatnonzero(dones.cpu().numpy())
        resets += len(done_ids)
        onnx_runner.reset(done_ids)
    if max(act_diff, eta_diff) > atol:
        diffs = f"{act_diff:.3g} (actions), {eta_diff:.3g} (eta)"
        raise ParityError(f"OnnxPolicyRunner vs torch student on env observations: {diffs} > {atol:.1g}")
    return {
        "rollout_onnx_max_abs_diff": act_diff,
        "rollout_eta_max_abs_diff": eta_diff,
        "student_teacher_action_mse": float(np.mean(action_err)),
        "decoded_eta_mae": float(np.mean(eta_err)),
        "rollout_resets": float(resets),
    }
