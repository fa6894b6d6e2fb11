# SPDX-License-Identifier: Apache-2.0
"""Training entry point: ``train(TrainRunCfg) -> dict[str, float]`` (PPO on the granular G1 task).

A run lives in one directory. Calling :func:`train` again with the same config resumes from the newest
checkpoint there and continues until ``max_iterations`` iterations are done in total, so a killed or
time-boxed run is continued by repeating the same call. A call with another config, or a run directory whose
checkpoints are damaged, is handled by :mod:`gmloco.train.resume` before anything is written.

With ``gpus`` naming several GPUs the call trains data-parallel (:mod:`gmloco.train.multi_gpu`): one rank per
GPU, each with the full ``num_envs``, gradients all-reduced, files written by rank 0 only; it resumes as a
one-GPU run does (from the same checkpoints, with any number of GPUs).
"""

from __future__ import annotations

import copy
import json
import math
import os
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

from gmloco.train.config import GranularTaskCfg
from gmloco.train.multi_gpu import RankInfo, check_gpus, launch_ranks, rank_info, visible_devices
from gmloco.train.resume import check_resume_cfg, resumable_checkpoint
from gmloco.train.tasks.g1_jump.config import JumpTaskCfg

__all__ = ["TrainRunCfg", "train"]


@dataclass
class TrainRunCfg:
    """One PPO run on the granular G1 task."""

    task: GranularTaskCfg = field(default_factory=GranularTaskCfg)
    """Task: contact model, terrain, materials, DR, rewards."""
    jump: JumpTaskCfg | None = None
    """The jump imitation task (``gmloco.train.tasks.g1_jump``) instead of the velocity task; None: walk. Its
    ``base`` holds the contact model and DR; ``task`` is then unused. Needs ``export_onnx=False`` and
    ``history_length=0``."""
    num_envs: int = 4096
    """Number of parallel environments."""
    max_iterations: int = 30_000
    """Total PPO iterations of the run (over all resumed calls)."""
    max_minutes: float | None = None
    """Wall-clock budget of this call [min], env construction and export included; None: no limit."""
    seed: int = 42
    """Seed of the env (mjlab seeds numpy, torch and warp from it) and of PPO."""
    device: str = "cuda:0"
    """Torch / Warp device, e.g. "cuda:0" or "cpu"; unused when ``gpus`` is set."""
    gpus: tuple[int, ...] = ()
    """CUDA device indices to train on (indices into ``CUDA_VISIBLE_DEVICES``, as mjlab's ``--gpu-ids``): one GPU
    trains on ``cuda:<id>``; several train data-parallel, one rank per GPU, each stepping ``num_envs`` envs (so
    ``len(gpus) * num_envs`` envs per iteration) with the seed ``seed + rank``. Empty: train on ``device``."""
    run_dir: str = "runs/train/ppo_rft3d"
    """Run directory: checkpoints ``model_<it>.pt``, TensorBoard events, ``policy.onnx``, ``metrics.json``."""
    resume: bool = True
    """Continue from the newest checkpoint in ``run_dir`` if there is one."""
    save_interval: int = 50
    """Iterations between checkpoints (one is always written when the call ends)."""
    num_steps_per_env: int = 24
    """Env steps per env and iteration."""
    hidden_dims: tuple[int, ...] = (512, 256, 128)
    """Hidden layer widths of actor and critic."""
    logger: Literal["tensorboard", "wandb"] = "tensorboard"
    """rsl-rl log writer (wandb runs offline unless WANDB_MODE says otherwise)."""
    export_onnx: bool = True
    """Export ``policy.onnx`` (+ ``policy.json``) with deploy metadata when the call ends."""
    export_reserve_s: float = 30.0
    """Time kept free before the deadline for the final checkpoint and export [s]."""
    rsl_rl_overrides: dict[str, Any] = field(default_factory=dict)
    """Top-level entries that replace those of the PPO runner cfg, e.g. ``TeacherCfg().to_rsl_rl(ObsGroupsCfg())``
    (VAE teacher) or ``DistillCfg(...).to_rsl_rl(...)`` (student); empty: vanilla PPO."""
    history_length: int = 0
    """N of the env's ``history`` observation group ``[num_envs, N, 96]`` (teacher encoder, student); 0: none."""
    init_checkpoint: str | None = None
    """Checkpoint loaded (through the algorithm's ``load``) when ``run_dir`` has none yet, e.g. the teacher's
    ``model_<it>.pt`` for distillation; None: start from scratch."""
    warm_start_ppo: str | None = None
    """VAE teacher only: a vanilla-PPO checkpoint of the same task whose actor (stacked frames mapped onto one
    frame, latent inputs zero) and critic start the teacher when ``run_dir`` has no checkpoint
    (``gmloco.train.teacher_student.warm_start``); None: start from scratch."""
    warm_start_student_encoder: str | None = None
    """Student only, with ``init_checkpoint`` a teacher: an earlier student checkpoint whose history encoder (TCN +
    normalizer) replaces the fresh one when ``run_dir`` has no checkpoint (distilling from a new teacher); None: a
    fresh encoder."""
    allow_changed: tuple[str, ...] = ()
    """Dotted config keys (or prefixes, e.g. ``task.reward_weights``) a resumed call may change on purpose; any
    other change of :data:`gmloco.train.resume.RESUME_INVARIANT` is refused."""


def _make_env(cfg: TrainRunCfg) -> Any:
    """Build the mjlab env wrapped for rsl-rl."""
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.rl import RslRlVecEnvWrapper

    if cfg.jump is not None:
        from gmloco.train.tasks.g1_jump.env_cfgs import make_g1_jump_env_cfg

        env_cfg = make_g1_jump_env_cfg(cfg.jump, cfg.num_envs)
    else:
        from gmloco.train.tasks.g1_granular import make_g1_granular_env_cfg

        env_cfg = make_g1_granular_env_cfg(cfg.task, cfg.num_envs, cfg.history_length)
    env_cfg.seed = cfg.seed
    return RslRlVecEnvWrapper(ManagerBasedRlEnv(cfg=env_cfg, device=cfg.device))


def _make_runner(cfg: TrainRunCfg, env: Any, run_dir: Path) -> Any:
    """Build the time-boxed rsl-rl runner with GM-Loco's PPO settings."""
    from gmloco.train.rl.runner import GmlocoOnPolicyRunner
    from gmloco.train.tasks.g1_granular import make_g1_granular_ppo_cfg

    agent = make_g1_granular_ppo_cfg(experiment_name=run_dir.name, hidden_dims=cfg.hidden_dims)
    agent.seed, agent.save_interval, agent.logger = cfg.seed, cfg.save_interval, cfg.logger
    agent.num_steps_per_env, agent.max_iterations = cfg.num_steps_per_env, cfg.max_iterations
    runner = GmlocoOnPolicyRunner(env, asdict(agent) | copy.deepcopy(cfg.rsl_rl_overrides), str(run_dir), cfg.device)
    runner.add_git_repo_to_log(__file__)
    return runner


def _warm_start(runner: Any, env: Any, path: str, run_dir: Path, write: bool = True) -> None:
    """Start a VAE teacher from a PPO checkpoint; the record goes to ``run_dir/warm_start.json`` when ``write``."""
    from gmloco.train.teacher_student.warm_start import warm_start_from_ppo

    dims = env.unwrapped.observation_manager.group_obs_term_dim["actor"]
    record = warm_start_from_ppo(runner.alg, Path(path).resolve(), [int(d[-1]) for d in dims])
    if write:
        (run_dir / "warm_start.json").write_text(json.dumps(record, indent=1))


def _warm_start_encoder(runner: Any, path: str, run_dir: Path, write: bool = True) -> None:
    """Start a student's history encoder from an earlier student; the record goes to ``run_dir/warm_start.json``."""
    from gmloco.train.teacher_student.warm_start import student_encoder_from

    record = student_encoder_from(runner.alg, Path(path).resolve())
    if write:
        (run_dir / "warm_start.json").write_text(json.dumps(record, indent=1))


def train(cfg: TrainRunCfg, on_iteration: Callable[[int, int], None] | None = None) -> dict[str, float]:
    """Train (or resume) PPO on the granular G1 task and return summary metrics.

    Args:
        cfg: The run configuration.
        on_iteration: Called after each PPO iteration with (iterations done in total, ``max_iterations``); not
            called when several GPUs train (the iterations run in the worker processes).

    Returns:
        ``iterations_done`` (this call), ``iteration`` (total), ``mean_reward``, ``mean_episode_length``,
        ``env_steps_per_second``, ``seconds_per_iteration`` (+ collection / learning parts),
        ``env_steps``, ``stopped_by_deadline``, ``resumed_from_iteration``, ``wall_seconds`` (rank 0's, with env
        steps counted over all ranks).

    Raises:
        GpuSelectionError: If ``gpus`` names a GPU twice, a negative or missing id, or the machine has no CUDA.
    """
    check_gpus(cfg.gpus)
    if len(cfg.gpus) == 1:
        return _train(replace(cfg, device=f"cuda:{cfg.gpus[0]}"), rank_info(), on_iteration)
    if len(cfg.gpus) > 1 and not rank_info().distributed:
        return _launch(cfg)
    return _train(cfg, rank_info(), on_iteration)


def _launch(cfg: TrainRunCfg) -> dict[str, float]:
    """Start one rank per GPU of ``cfg.gpus`` and return rank 0's metrics.

    The run directory is checked and its damaged checkpoints are set aside here, before any worker starts, so every
    rank reads the same newest checkpoint.
    """
    run_dir = _prepare_run_dir(cfg)
    checkpoint, skipped = resumable_checkpoint(run_dir) if cfg.resume else (None, [])
    for line in skipped:
        print(f"train: {line}; resuming from {checkpoint}", file=sys.stderr)
    summary = launch_ranks(train_rank, cfg, len(cfg.gpus), visible_devices(cfg.gpus), str(run_dir / "torchrunx"))
    return summary | {"corrupt_checkpoints_skipped": float(len(skipped))}


def train_rank(cfg: TrainRunCfg) -> dict[str, float]:
    """Run one rank of a data-parallel run (the function the launcher starts in each worker).

    A GPU rank trains on ``cuda:<LOCAL_RANK>``; a run on ``device="cpu"`` keeps the CPU (the multi-process tests,
    with gloo). The seed is ``seed + RANK``, as in mjlab's train script, so the ranks explore differently.
    """
    ranks = rank_info()
    device = cfg.device if cfg.device.startswith("cpu") and not cfg.gpus else f"cuda:{ranks.local_rank}"
    try:
        return _train(replace(cfg, device=device), ranks, None)
    finally:
        import torch

        if torch.distributed.is_available() and torch.distributed.is_initialized():
            torch.distributed.destroy_process_group()


def _prepare_run_dir(cfg: TrainRunCfg) -> Path:
    """Create the run directory and check that it may be resumed with ``cfg`` (writes ``train_cfg.json``)."""
    run_dir = Path(cfg.run_dir).resolve()
    run_dir.mkdir(parents=True, exist_ok=True)
    if cfg.jump is not None and (cfg.export_onnx or cfg.history_length > 0):
        raise ValueError(
            "the jump task has no ONNX deploy metadata and no history group: set export_onnx=False and "
            "history_length=0 in TrainRunCfg"
        )
    as_json = lambda c: json.loads(json.dumps(asdict(c), default=str))  # noqa: E731
    check_resume_cfg(run_dir, as_json(cfg), cfg.allow_changed, defaults=as_json(TrainRunCfg()))
    return run_dir


def _train(cfg: TrainRunCfg, ranks: RankInfo, on_iteration: Callable[[int, int], None] | None) -> dict[str, float]:
    """Train on ``cfg.device`` as rank ``ranks.rank`` of ``ranks.world_size`` (see :func:`train`)."""
    start = time.monotonic()
    deadline = None if cfg.max_minutes is None else start + 60.0 * cfg.max_minutes - cfg.export_reserve_s
    os.environ.setdefault("WANDB_MODE", "offline")
    os.environ.setdefault("GIT_PYTHON_REFRESH", "quiet")
    if ranks.writes:
        run_dir = _prepare_run_dir(cfg)
        checkpoint, skipped = resumable_checkpoint(run_dir) if cfg.resume else (None, [])
    else:  # rank 0 checks the run directory and sets damaged checkpoints aside; the others only read it
        from gmloco.train.rl.runner import latest_checkpoint

        run_dir, skipped = Path(cfg.run_dir).resolve(), []
        checkpoint = latest_checkpoint(run_dir) if cfg.resume else None
    for line in skipped:
        print(f"train: {line}; resuming from {checkpoint}", file=sys.stderr)

    from gmloco.train.rl.export import export_policy_onnx

    env = _make_env(replace(cfg, seed=cfg.seed + ranks.rank))
    runner = _make_runner(replace(cfg, seed=cfg.seed + ranks.rank), env, run_dir)
    if checkpoint is not None:
        runner.load(str(checkpoint))
    elif cfg.init_checkpoint is not None:
        runner.load(str(Path(cfg.init_checkpoint).resolve()))
        if cfg.warm_start_student_encoder is not None:
            _warm_start_encoder(runner, cfg.warm_start_student_encoder, run_dir, ranks.writes)
    elif cfg.warm_start_ppo is not None:
        _warm_start(runner, env, cfg.warm_start_ppo, run_dir, ranks.writes)
    resumed_from = runner.current_learning_iteration
    remaining = cfg.max_iterations - resumed_from
    if remaining > 0:
        runner.learn(remaining, init_at_random_ep_len=checkpoint is None, deadline=deadline, on_iteration=on_iteration)
    summary = runner.summary() if remaining > 0 else {"iterations_done": 0.0, "iteration": float(resumed_from)}
    if cfg.export_onnx and ranks.writes:
        extra = {"contact_model": cfg.task.contact_model, "terrain": cfg.task.terrain.kind}
        export_policy_onnx(runner, run_dir / "policy.onnx", cfg.task, run_name=run_dir.name, extra=extra)
    env.close()
    summary.update(resumed_from_iteration=float(resumed_from), wall_seconds=time.monotonic() - start)
    summary["corrupt_checkpoints_skipped"] = float(len(skipped))
    if ranks.writes:
        clean = {k: (v if math.isfinite(v) else None) for k, v in summary.items()}
        (run_dir / "metrics.json").write_text(json.dumps(clean, indent=1))
    return summary
