# SPDX-License-Identifier: Apache-2.0
"""Shared fixtures of the train tests: CPU device, quiet Warp, one G1 env cache per pytest process.

Building the first mjlab env compiles MuJoCo Warp (25-70 s on CPU; ``WARP_CACHE_PATH`` is honoured by Warp
itself); later builds in the same process take a few seconds, so env-building tests share the
session-scoped :func:`make_env` factory and every module that needs an env builds it once.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from typing import Any

import pytest
import warp as wp

wp.config.quiet = True
if os.environ.get("WARP_CACHE_PATH"):
    wp.config.kernel_cache_dir = os.environ["WARP_CACHE_PATH"]
os.environ.setdefault("MUJOCO_GL", "disable")
os.environ.setdefault("WANDB_MODE", "offline")

DEVICE = "cpu"
"""Device of every train test."""


@pytest.fixture(scope="session")
def device() -> str:
    """Torch / Warp device used by the tests."""
    wp.init()
    return DEVICE


@pytest.fixture(scope="session")
def make_env(device: str) -> Iterator[Callable[..., Any]]:
    """Return ``make_env(task, num_envs=2)`` building a ``ManagerBasedRlEnv``; all are closed at the end."""
    from mjlab.envs import ManagerBasedRlEnv

    from gmloco.train import make_g1_granular_env_cfg

    built: list[Any] = []

    def _make(task: Any, num_envs: int = 2, seed: int = 0) -> Any:
        cfg = make_g1_granular_env_cfg(task, num_envs)
        cfg.seed = seed
        env = ManagerBasedRlEnv(cfg=cfg, device=device)
        built.append(env)
        return env

    yield _make
    for env in built:
        env.close()
