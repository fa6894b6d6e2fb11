# SPDX-License-Identifier: Apache-2.0
"""Helpers for the pipeline tests: plain-python subprocesses and two toy stages that really write outputs.

The runner's skip/resume/force logic is exercised in seconds with a toy ``train_teacher`` (writes a checkpoint) and
a toy ``distill`` (reads it, writes a student) registered in place of the real ones; the later stages are
registered as not implemented, so these tests never run the real (minutes-long) stages. ``test_pipeline_smoke.py``
and ``test_stage_rerun.py`` run the real ones.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from workflows import stage_registry
from workflows.run_dir import atomic_write_json, read_json
from workflows.stage_registry import StageFn, StageSpec, not_implemented

REPO_ROOT = Path(__file__).resolve().parents[1]
"""Checkout root."""

CALLS: Counter[str] = Counter()
"""How often each toy stage ran in this process."""


def plain_python_env(**extra: str) -> dict[str, str]:
    """Environment for ``python workflows/...`` without uv: ``PYTHONPATH=packages/*/src:workflows`` (+ root)."""
    srcs = sorted(str(p) for p in (REPO_ROOT / "packages").glob("*/src"))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([*srcs, str(REPO_ROOT / "workflows"), str(REPO_ROOT)])
    env["WANDB_MODE"] = "disabled"
    env.update(extra)
    return env


def run_cli(
    args: Sequence[str], timeout: float = 600, env: Mapping[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    """Run ``python <args>`` from the checkout root and capture its output."""
    return subprocess.run(
        [sys.executable, *args],
        cwd=REPO_ROOT,
        env=dict(env or plain_python_env()),
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )


def toy_teacher(cfg: Any) -> dict[str, float]:
    """Toy train_teacher: write a checkpoint that depends on the config, return a metric."""
    CALLS["train_teacher"] += 1
    out = Path(cfg.train_teacher.out_dir)
    atomic_write_json(out / "checkpoint.json", {"seed": cfg.seed, "num_envs": cfg.train_teacher.num_envs})
    return {"mean_reward": 1.5, "max_minutes": float(cfg.train_teacher.max_minutes or -1.0)}


def toy_student(cfg: Any) -> dict[str, float]:
    """Toy distill: read the teacher checkpoint, write a student; hang when ``TOY_HANG=1`` (kill tests)."""
    CALLS["distill"] += 1
    while os.environ.get("TOY_HANG") == "1":
        time.sleep(0.1)
    teacher = read_json(Path(cfg.distill.teacher_dir) / "checkpoint.json")
    atomic_write_json(Path(cfg.distill.out_dir) / "student.json", {"teacher": teacher})
    return {"action_loss": 0.25}


def toy_registry(teacher: StageFn = toy_teacher, student: StageFn = toy_student) -> tuple[StageSpec, ...]:
    """The real registry with train_teacher and distill replaced by toy stages and the rest by stubs."""
    real = {s.name: s for s in stage_registry.STAGES}
    return (
        StageSpec("train_teacher", real["train_teacher"].issues, (), "toy teacher", fn=teacher),
        StageSpec("distill", real["distill"].issues, ("train_teacher",), "toy student", fn=student),
        *(StageSpec(s.name, s.issues, s.needs, "stub", fn=not_implemented(s.name)) for s in stage_registry.STAGES[2:]),
    )
