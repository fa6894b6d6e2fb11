# SPDX-License-Identifier: Apache-2.0
"""Warm starts: the VAE teacher from a PPO actor (exact on a stationary history), a student's encoder from a student."""

from __future__ import annotations

import copy
from collections.abc import Callable
from pathlib import Path

import pytest
import torch
from rsl_rl.env import VecEnv
from torch import nn

from gmloco.train.teacher_student import (
    ObsGroupsCfg,
    StudentPPO,
    TeacherCfg,
    TeacherPPO,
)
from gmloco.train.teacher_student.checkpoint_teacher import detach_teacher
from gmloco.train.teacher_student.warm_start import (
    STUDENT_ENCODER_PREFIXES,
    stacked_columns,
    student_encoder_from,
    teacher_actor_from_ppo,
)

FRAMES = 3
TERM_DIMS = (2, 3)  # the toy env's actor frame: command (2) + noise (3)


def test_stacked_columns_follow_mjlabs_term_major_layout() -> None:
    """Term a (2 wide) then term b (1 wide), 3 frames: [a0 a0' a1 a1' a2 a2' | b0 b1 b2]."""
    cols = stacked_columns((2, 1), 3)
    assert cols.tolist() == [[0, 1, 6], [2, 3, 7], [4, 5, 8]]


def _ppo_state(teacher: dict[str, torch.Tensor], in_dim: int, gen: torch.Generator) -> dict[str, torch.Tensor]:
    """A random PPO actor state over ``in_dim`` stacked inputs with the teacher's hidden layers."""
    ppo = {k: torch.randn(v.shape, generator=gen) for k, v in teacher.items() if k.startswith(("mlp.", "distribution"))}
    ppo["mlp.0.weight"] = torch.randn(teacher["mlp.0.weight"].shape[0], in_dim, generator=gen)
    std = torch.rand(1, in_dim, generator=gen) + 0.5
    ppo |= {
        "obs_normalizer._mean": torch.randn(1, in_dim, generator=gen),
        "obs_normalizer._var": std**2,
        "obs_normalizer._std": std,
        "obs_normalizer.count": torch.tensor(1000),
    }
    return ppo


def test_warm_started_teacher_acts_like_the_ppo_actor_on_a_stationary_history(
    toy_env: VecEnv, teacher_cfg: TeacherCfg, groups: ObsGroupsCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """Teacher(o_t, z) == PPO([o_t] * H) for any z, since the latent columns start at zero."""
    alg: TeacherPPO = TeacherPPO.construct_algorithm(  # type: ignore[assignment]
        toy_env.get_observations(), toy_env, runner_cfg(teacher_cfg.to_rsl_rl(groups)), "cpu"
    )
    actor = alg.actor
    frame = sum(TERM_DIMS)
    gen = torch.Generator().manual_seed(0)
    ppo = _ppo_state(actor.state_dict(), FRAMES * frame, gen)
    actor.load_state_dict(teacher_actor_from_ppo(ppo, actor.state_dict(), TERM_DIMS), strict=True)

    x = torch.randn(7, frame, generator=gen)
    stack = torch.empty(7, FRAMES * frame)
    for cols in stacked_columns(TERM_DIMS, FRAMES):
        stack[:, cols] = x
    ppo_mlp = copy.deepcopy(actor.mlp)
    ppo_mlp[0] = nn.Linear(FRAMES * frame, ppo["mlp.0.weight"].shape[0])
    ppo_mlp.load_state_dict({k[4:]: v for k, v in ppo.items() if k.startswith("mlp.")})
    expected = ppo_mlp((stack - ppo["obs_normalizer._mean"]) / (ppo["obs_normalizer._std"] + 1e-2))

    z = torch.randn(7, actor.latent_dim, generator=gen)
    got = actor.mlp(torch.cat([actor.obs_normalizer(x), z], dim=-1))
    torch.testing.assert_close(got, expected, rtol=1e-5, atol=1e-5)
    torch.testing.assert_close(actor.distribution.std_param, ppo["distribution.std_param"])  # type: ignore[union-attr]


def test_warm_start_refuses_a_ppo_input_that_is_not_whole_frames(
    toy_env: VecEnv, teacher_cfg: TeacherCfg, groups: ObsGroupsCfg, runner_cfg: Callable[[dict], dict]
) -> None:
    """A 14-wide PPO input is not a stack of 5-wide frames: say so instead of mis-mapping columns."""
    alg = TeacherPPO.construct_algorithm(
        toy_env.get_observations(), toy_env, runner_cfg(teacher_cfg.to_rsl_rl(groups)), "cpu"
    )
    state = alg.actor.state_dict()
    with pytest.raises(ValueError, match="not a stack"):
        teacher_actor_from_ppo(_ppo_state(state, 14, torch.Generator().manual_seed(1)), state, TERM_DIMS)


def test_student_encoder_warm_start_copies_only_the_history_encoder(
    student_alg: StudentPPO, new_student: Callable[[int], StudentPPO], teacher_ckpt: dict, tmp_path: Path
) -> None:
    """A new student from a (new) teacher takes the earlier student's TCN and history normalizer, nothing else."""
    earlier = student_alg.save()
    with torch.no_grad():
        for key, value in earlier["actor_state_dict"].items():
            if torch.is_floating_point(value):
                earlier["actor_state_dict"][key] = value + 0.5  # distinct from any fresh initialisation
    path = tmp_path / "student.pt"
    torch.save(earlier, path)
    new = new_student(7)
    new.load(teacher_ckpt, None, strict=True)
    before = {k: v.clone() for k, v in new.actor.state_dict().items()}
    record = student_encoder_from(new, path)
    after = new.actor.state_dict()
    copied = {k for k in after if k.startswith(STUDENT_ENCODER_PREFIXES)}
    assert copied and record["entries"] == len(copied)
    for key, value in after.items():
        expected = earlier["actor_state_dict"][key] if key in copied else before[key]
        assert torch.equal(value, expected), key


def test_student_encoder_warm_start_refuses_a_teacher_checkpoint(
    student_alg: StudentPPO, teacher_ckpt: dict, tmp_path: Path
) -> None:
    """A teacher checkpoint has no student encoder: refused with the reason."""
    path = tmp_path / "teacher.pt"
    torch.save(teacher_ckpt, path)
    with pytest.raises(ValueError, match="not a student checkpoint"):
        student_encoder_from(student_alg, path)


def test_student_encoder_warm_start_refuses_another_latent_size(student_alg: StudentPPO, tmp_path: Path) -> None:
    """An encoder of another latent size cannot be copied: refused, naming the entries."""
    saved = student_alg.save()
    saved["actor_state_dict"]["encoder.mlp.2.weight"] = torch.zeros(3, 1)
    path = tmp_path / "student.pt"
    torch.save(saved, path)
    with pytest.raises(ValueError, match="does not fit"):
        student_encoder_from(student_alg, path)


def test_student_encoder_warm_start_takes_a_student_whose_teacher_is_detached(
    student_alg: StudentPPO, new_student: Callable[[int], StudentPPO], teacher_ckpt: dict, tmp_path: Path
) -> None:
    """Committed students carry no teacher (they name its file): their encoder is still a valid warm start."""
    teacher_path = tmp_path / "teacher.pt"
    torch.save(teacher_ckpt, teacher_path)
    path = tmp_path / "student.pt"
    torch.save(detach_teacher(student_alg.save(), teacher_path), path)
    new = new_student(7)
    new.load(teacher_ckpt, None, strict=True)
    assert student_encoder_from(new, path)["entries"] > 0
