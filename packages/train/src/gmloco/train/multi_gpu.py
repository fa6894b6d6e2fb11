# SPDX-License-Identifier: Apache-2.0
"""Data-parallel training on several GPUs: mjlab's launcher (torchrunx) and rsl-rl's rank contract.

mjlab's train script (``mjlab.scripts.train``, ``--gpu-ids``) starts one worker process per GPU with torchrunx and
lets rsl-rl open the process group. Each worker reads ``RANK`` / ``LOCAL_RANK`` / ``WORLD_SIZE``, runs the full env
count on ``cuda:<LOCAL_RANK>`` with the seed ``seed + RANK``, and rsl-rl's ``OnPolicyRunner`` broadcasts rank 0's
parameters before learning, all-reduces the gradients of every mini-batch and the KL of the adaptive learning rate
(so every rank takes the same optimizer step), and disables logging on ranks other than 0. gmloco keeps that
contract: only rank 0 writes checkpoints, logs, metrics and exports.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

__all__ = [
    "GpuSelectionError",
    "RankInfo",
    "any_rank",
    "check_gpus",
    "cuda_device_count",
    "gpus_problem",
    "launch_ranks",
    "rank_info",
    "visible_devices",
]

_Arg = TypeVar("_Arg")
_Result = TypeVar("_Result")

COPIED_ENV_VARS = ("MUJOCO*", "WARP*", "WANDB*", "GIT_PYTHON*")
"""Environment variables the workers get besides torchrunx's defaults (``PATH``, ``PYTHON*``, ``CUDA*``, ...);
mjlab's train script adds ``MUJOCO*``."""


class GpuSelectionError(ValueError):
    """A ``gpus`` list that cannot be used on this machine."""


@dataclass(frozen=True)
class RankInfo:
    """Where this process sits in a data-parallel run (rsl-rl's environment variables)."""

    rank: int
    """Global rank (``RANK``); rank 0 writes every file."""
    local_rank: int
    """Rank on this host (``LOCAL_RANK``); a GPU rank trains on ``cuda:<local_rank>``."""
    world_size: int
    """Number of ranks (``WORLD_SIZE``); 1: no data parallelism."""

    @property
    def distributed(self) -> bool:
        """Whether several ranks train together."""
        return self.world_size > 1

    @property
    def writes(self) -> bool:
        """Whether this rank writes the run's files (rank 0 only)."""
        return self.rank == 0


def rank_info() -> RankInfo:
    """Read this process's rank from ``RANK``, ``LOCAL_RANK`` and ``WORLD_SIZE`` (defaults: one rank)."""
    env = os.environ
    return RankInfo(int(env.get("RANK", "0")), int(env.get("LOCAL_RANK", "0")), int(env.get("WORLD_SIZE", "1")))


def cuda_device_count() -> int:
    """Number of CUDA devices torch sees (0 without CUDA)."""
    import torch

    return torch.cuda.device_count() if torch.cuda.is_available() else 0


def gpus_problem(gpus: Sequence[int], device_count: int) -> str | None:
    """Why ``gpus`` cannot be used with ``device_count`` visible CUDA devices (one clause); None when it can.

    ``gpus`` are indices into ``CUDA_VISIBLE_DEVICES`` (torch's ``cuda:<i>``), as mjlab's ``--gpu-ids``.
    """
    ids = list(gpus)
    if not ids:
        return None
    if negative := [g for g in ids if g < 0]:
        return f"negative GPU ids {negative}; name CUDA device indices 0, 1, ..."
    if duplicates := sorted({g for g in ids if ids.count(g) > 1}):
        return f"GPU ids {duplicates} are named more than once; each GPU runs one rank"
    if device_count == 0:
        return "this machine has no CUDA device; leave gpus empty to train on the configured device (e.g. cpu)"
    if missing := [g for g in ids if g >= device_count]:
        return (
            f"GPU ids {missing} do not exist: this machine has {device_count} CUDA device(s), ids 0..{device_count - 1}"
        )
    return None


def check_gpus(gpus: Sequence[int], device_count: int | None = None) -> None:
    """Raise :class:`GpuSelectionError` when ``gpus`` cannot be used here.

    Args:
        gpus: CUDA device indices; empty is always valid (train on the configured device).
        device_count: Visible CUDA devices; None: ask torch.
    """
    if not gpus:
        return
    problem = gpus_problem(gpus, cuda_device_count() if device_count is None else device_count)
    if problem is not None:
        raise GpuSelectionError(f"bad value for 'gpus' {list(gpus)}: {problem}.")


def visible_devices(gpus: Sequence[int]) -> str:
    """``CUDA_VISIBLE_DEVICES`` of the workers: the physical ids of ``gpus`` (mjlab's ``select_gpus``)."""
    from mjlab.utils.gpu import select_gpus

    selected, _ = select_gpus(list(gpus))
    return ",".join(str(g) for g in selected or [])


def launch_ranks(
    fn: Callable[[_Arg], _Result], arg: _Arg, workers: int, cuda_visible_devices: str | None, log_dir: str
) -> _Result:
    """Run ``fn(arg)`` in ``workers`` processes on this host with torchrunx, as mjlab's train script; return rank 0's.

    torchrunx sets ``RANK`` / ``LOCAL_RANK`` / ``WORLD_SIZE`` / ``MASTER_ADDR`` / ``MASTER_PORT`` in each worker and
    opens no process group (``backend=None``): rsl-rl's runner opens it. A worker's exception is raised here.

    Args:
        fn: Picklable function run by every worker.
        arg: Its argument.
        workers: Number of ranks.
        cuda_visible_devices: ``CUDA_VISIBLE_DEVICES`` of the workers (local rank i uses the i-th); None: inherited.
        log_dir: Folder of the workers' logs when ``TORCHRUNX_LOG_DIR`` is not set (mjlab: ``<run>/torchrunx``).
    """
    import torchrunx

    logging.basicConfig(level=logging.INFO)  # torchrunx forwards the workers' output through logging
    extra = None if cuda_visible_devices is None else {"CUDA_VISIBLE_DEVICES": cuda_visible_devices}
    launcher = torchrunx.Launcher(
        hostnames=["localhost"],
        workers_per_host=workers,
        backend=None,
        copy_env_vars=torchrunx.DEFAULT_ENV_VARS_FOR_COPY + COPIED_ENV_VARS,
        extra_env_vars=extra,
    )
    # torchrunx reads the log folder from the environment when it starts; set it for this launch only, so the
    # next stage of a pipeline logs to its own folder
    own_log_dir = "TORCHRUNX_LOG_DIR" not in os.environ
    if own_log_dir:
        os.environ["TORCHRUNX_LOG_DIR"] = log_dir
    try:
        return launcher.run(fn, arg).rank(0)
    finally:
        if own_log_dir:
            os.environ.pop("TORCHRUNX_LOG_DIR", None)


def any_rank(flag: bool, device: Any) -> bool:
    """Whether ``flag`` is true on any rank (all-reduce MAX); ``flag`` itself outside a process group.

    A decision that ends the loop (the time box) must be taken by all ranks at once, or the others wait forever in
    the next gradient all-reduce.
    """
    import torch

    if not (torch.distributed.is_available() and torch.distributed.is_initialized()):
        return flag
    value = torch.tensor([float(flag)], device=device)
    torch.distributed.all_reduce(value, op=torch.distributed.ReduceOp.MAX)
    return bool(value.item() > 0.0)
