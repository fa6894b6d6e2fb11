# SPDX-License-Identifier: Apache-2.0
"""End to end on the toy env: rsl-rl's runner trains the teacher, StudentRunner loads it and distils."""

from __future__ import annotations

import contextlib
import io
from collections.abc import Callable
from pathlib import Path

import pytest
import torch
from rsl_rl.env import VecEnv
from rsl_rl.runners import OnPolicyRunner

from gmloco.train.teacher_student import DistillCfg, ObsGroupsCfg, StudentCfg, StudentRunner, TeacherCfg

BEST_BLIND_ERROR = (2.0 / 3.0) * (1.0 / 12.0)
"""Action error of the best policy that ignores eta: E||c||^2 Var(eta) = (2 * 1/3) * (1/12) ~ 0.056."""


def _quiet(fn: Callable[[], object]) -> object:
    """Run ``fn`` with rsl-rl's model printouts silenced."""
    with contextlib.redirect_stdout(io.StringIO()):
        return fn()


def _action_error(actor: torch.nn.Module, make_env: type[VecEnv]) -> float:
    """Mean ||a - a*||^2 of the deterministic actor on 512 fresh toy states."""
    env = make_env(num_envs=512, seed=123)  # type: ignore[call-arg]
    with torch.no_grad():
        actions = actor.eval()(env.get_observations())
    actor.train()
    return (actions - env.best_action()).pow(2).sum(-1).mean().item()  # type: ignore[attr-defined]


def _train_teacher(
    env: VecEnv, cfg: TeacherCfg, groups: ObsGroupsCfg, complete: Callable[[dict], dict], iterations: int, path: Path
) -> OnPolicyRunner:
    """Train TeacherPPO with rsl-rl's stock OnPolicyRunner and save a checkpoint at ``path``."""
    runner: OnPolicyRunner = _quiet(lambda: OnPolicyRunner(env, complete(cfg.to_rsl_rl(groups)), log_dir=None))  # type: ignore[assignment]
    _quiet(lambda: runner.learn(iterations))
    runner.save(str(path))
    return runner


def test_student_runner_loads_the_teacher_checkpoint_and_distils(
    tmp_path: Path,
    make_env: type[VecEnv],
    teacher_cfg: TeacherCfg,
    student_cfg: StudentCfg,
    distill_cfg: DistillCfg,
    groups: ObsGroupsCfg,
    runner_cfg: Callable[[dict], dict],
) -> None:
    """Teacher file -> StudentRunner(teacher_checkpoint=...) -> learn; checkpoint keeps env counter and teacher."""
    torch.manual_seed(0)
    _train_teacher(make_env(), teacher_cfg, groups, runner_cfg, 1, tmp_path / "teacher.pt")  # type: ignore[call-arg]
    distill_cfg.teacher_checkpoint = str(tmp_path / "teacher.pt")
    env = make_env(seed=3)  # type: ignore[call-arg]
    cfg = runner_cfg(distill_cfg.to_rsl_rl(teacher_cfg, student_cfg, groups))
    runner: StudentRunner = _quiet(lambda: StudentRunner(env, cfg, log_dir=None))  # type: ignore[assignment]
    assert runner.alg.teacher_loaded
    _quiet(lambda: runner.learn(2))
    runner.save(str(tmp_path / "student.pt"))
    saved = torch.load(tmp_path / "student.pt", weights_only=False)
    assert saved["infos"]["env_state"]["common_step_counter"] == env.common_step_counter > 0  # type: ignore[attr-defined]
    assert saved["distill_updates"] == 2 and "teacher_state_dict" in saved


def test_student_runner_refuses_to_learn_without_a_teacher(
    make_env: type[VecEnv],
    teacher_cfg: TeacherCfg,
    student_cfg: StudentCfg,
    distill_cfg: DistillCfg,
    groups: ObsGroupsCfg,
    runner_cfg: Callable[[dict], dict],
) -> None:
    """No teacher_checkpoint and no load_teacher(): learn() raises before collecting anything."""
    cfg = runner_cfg(distill_cfg.to_rsl_rl(teacher_cfg, student_cfg, groups))
    runner: StudentRunner = _quiet(lambda: StudentRunner(make_env(), cfg, log_dir=None))  # type: ignore[assignment]
    with pytest.raises(ValueError, match="No teacher loaded"):
        runner.learn(1)


def test_toy_teacher_and_student_learn_to_use_eta(
    tmp_path: Path,
    make_env: type[VecEnv],
    teacher_cfg: TeacherCfg,
    student_cfg: StudentCfg,
    distill_cfg: DistillCfg,
    groups: ObsGroupsCfg,
    runner_cfg: Callable[[dict], dict],
) -> None:
    """Both policies beat the best eta-blind policy (~0.056): the teacher via z, the student via z_hat.

    The best action is command * (0.5 + eta); eta reaches the teacher only through its encoder (privileged group)
    and the student only through the history. About 6 s on 2 idle CPU cores.
    """
    torch.manual_seed(0)
    teacher_cfg.kl_weight = 1e-4
    teacher_cfg.ppo.num_learning_epochs, teacher_cfg.ppo.schedule = 4, "fixed"
    teacher = _train_teacher(make_env(num_envs=64), teacher_cfg, groups, runner_cfg, 15, tmp_path / "t.pt")  # type: ignore[call-arg]
    assert _action_error(teacher.alg.actor, make_env) < 0.5 * BEST_BLIND_ERROR
    distill_cfg.teacher_checkpoint = str(tmp_path / "t.pt")
    distill_cfg.ppo.num_learning_epochs = 4
    cfg = runner_cfg(distill_cfg.to_rsl_rl(teacher_cfg, student_cfg, groups))
    student: StudentRunner = _quiet(lambda: StudentRunner(make_env(num_envs=64, seed=5), cfg, log_dir=None))  # type: ignore[call-arg,assignment]
    _quiet(lambda: student.learn(10))
    assert _action_error(student.alg.actor, make_env) < 0.5 * BEST_BLIND_ERROR


def test_a_checkpoint_without_optimizer_state_loads_with_a_fresh_optimizer(
    teacher_ckpt: dict, toy_env: VecEnv, teacher_cfg: TeacherCfg, groups: ObsGroupsCfg, runner_cfg: Callable
) -> None:
    """A slim artifact (no ``optimizer_state_dict``) restores the weights and leaves Adam untouched (empty state)."""
    from gmloco.train.teacher_student import TeacherPPO

    slim = {k: v for k, v in teacher_ckpt.items() if k != "optimizer_state_dict"}
    alg = TeacherPPO.construct_algorithm(
        toy_env.get_observations(), toy_env, runner_cfg(teacher_cfg.to_rsl_rl(groups)), "cpu"
    )
    assert alg.load(slim, None, strict=True)  # the iteration is still restored
    for name, value in alg.actor.state_dict().items():
        torch.testing.assert_close(value, slim["actor_state_dict"][name], rtol=0.0, atol=0.0)
    assert alg.optimizer.state_dict()["state"] == {}
