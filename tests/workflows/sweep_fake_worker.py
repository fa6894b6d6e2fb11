# SPDX-License-Identifier: Apache-2.0
"""``workflows/sweep.py``'s command with the training replaced by a cheap deterministic function (sweep tests).

Run as ``python tests/workflows/sweep_fake_worker.py <the sweep's overrides>``: the same Hydra entry, study,
trial folders, chunked reports and pruner as the real command; only ``train_teacher.run_training`` (seconds
to hours of PPO) becomes ``mean_reward = mu_int low end x iteration`` and the task factory skips mjlab.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from omegaconf import DictConfig

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from workflows import policy_training, sweep, train_teacher


def fake_run_training(cfg: DictConfig, name: str, **kwargs: Any) -> dict[str, float]:
    """Write ``model_<iteration>.pt``; return ``mean_reward`` = the trial's ``mu_int`` low end x iteration."""
    section = cfg[name]
    out = Path(section.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    it = int(section.max_iterations)
    (out / f"model_{it}.pt").write_text("checkpoint")
    return {"iteration": float(it), "mean_reward": float(kwargs["task"].material.mu_int[0]) * it}


def _granular_task(section: DictConfig) -> Any:
    """The default task config (the real factory builds the mjlab task first)."""
    from gmloco.train.config import GranularTaskCfg

    return GranularTaskCfg()


def _install() -> None:
    """Replace the training and the task factory in this process."""
    train_teacher.run_training = fake_run_training
    policy_training.task_cfg = _granular_task


def gpu_worker(cfg: DictConfig) -> int:
    """``sweep._gpu_worker`` with the cheap training (the body of a spawned worker process)."""
    _install()
    return sweep._gpu_worker(cfg)


if __name__ == "__main__":
    _install()
    sweep.main()
