# SPDX-License-Identifier: Apache-2.0
"""Tiny CPU fixtures for the teacher-student tests: a toy terrain bandit env and [32, 32] model cfgs."""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace

import pytest
import torch
from rsl_rl.env import VecEnv
from tensordict import TensorDict

from gmloco.train.teacher_student import (
    DistillCfg,
    ObsGroupsCfg,
    PpoCfg,
    PpoSchedule,
    StudentCfg,
    StudentPPO,
    TeacherActor,
    TeacherCfg,
    TeacherPPO,
)

NUM_ENVS = 16
NUM_ACTIONS = 2
OBS_DIM = 5  # command (2) + 3 noise features
HISTORY = 8
LATENT = 3


class ToyTerrainEnv(VecEnv):
    """Contextual bandit with a hidden terrain stiffness eta ~ U[0, 1] per env.

    o_t = [command (A), noise (3)]; the best action is ``command * (0.5 + eta)``, so o_t alone cannot act well.
    eta sits in the last column of the privileged ``critic`` group, and echoes (noisily) in the last feature of
    every history frame, so a history encoder can infer it. Every step is a one-step episode (dones = 1).
    """

    def __init__(self, num_envs: int = NUM_ENVS, seed: int = 0) -> None:
        """Seed the generator and draw the first observation."""
        self.num_envs, self.num_actions = num_envs, NUM_ACTIONS
        self.max_episode_length = 1
        self.episode_length_buf = torch.zeros(num_envs, dtype=torch.long)
        self.device, self.cfg = "cpu", {}
        self.common_step_counter = 0
        self.gen = torch.Generator().manual_seed(seed)
        self._resample()

    def _rand(self, *shape: int) -> torch.Tensor:
        """Uniform [0, 1) draw from the env's generator."""
        return torch.rand(*shape, generator=self.gen)

    def _resample(self) -> None:
        """Draw command, eta and the observation groups."""
        n = self.num_envs
        self.command = 2.0 * self._rand(n, NUM_ACTIONS) - 1.0
        self.eta = self._rand(n, 1)
        actor = torch.cat([self.command, self._rand(n, OBS_DIM - NUM_ACTIONS)], dim=-1)
        history = self._rand(n, HISTORY, OBS_DIM)
        history[..., -1] = self.eta + 0.05 * (self._rand(n, HISTORY) - 0.5)
        self.obs = TensorDict(
            {"actor": actor, "critic": torch.cat([actor, self.eta], -1), "history": history}, batch_size=[n]
        )

    def best_action(self) -> torch.Tensor:
        """Return the optimal action ``command * (0.5 + eta)``, ``[num_envs, A]``."""
        return self.command * (0.5 + self.eta)

    def get_observations(self) -> TensorDict:
        """Return the current observation groups."""
        return self.obs

    def step(self, actions: torch.Tensor) -> tuple[TensorDict, torch.Tensor, torch.Tensor, dict]:
        """Reward -||a - a*||^2, then a fresh one-step episode."""
        reward = -(actions - self.best_action()).pow(2).sum(-1)
        self.common_step_counter += 1
        self._resample()
        return self.obs, reward, torch.ones(self.num_envs, dtype=torch.long), {}


@pytest.fixture
def dims() -> SimpleNamespace:
    """Sizes of the toy problem (test modules cannot import conftest under importlib mode)."""
    return SimpleNamespace(num_envs=NUM_ENVS, num_actions=NUM_ACTIONS, obs_dim=OBS_DIM, history=HISTORY, latent=LATENT)


@pytest.fixture
def make_env() -> type[ToyTerrainEnv]:
    """The toy env class, to build extra seeded instances."""
    return ToyTerrainEnv


@pytest.fixture
def toy_env() -> ToyTerrainEnv:
    """A seeded toy terrain env with 16 envs."""
    torch.manual_seed(0)
    return ToyTerrainEnv()


@pytest.fixture
def groups() -> ObsGroupsCfg:
    """The default observation-group names (actor / critic / history, eta last in critic)."""
    return ObsGroupsCfg()


@pytest.fixture
def teacher_cfg() -> TeacherCfg:
    """A [32, 32] teacher."""
    ppo = PpoCfg(num_learning_epochs=2, num_mini_batches=2, learning_rate=3e-3, entropy_coef=0.0)
    return TeacherCfg(
        actor_hidden_dims=(32, 32),
        critic_hidden_dims=(32, 32),
        encoder_hidden_dims=(32, 16),
        decoder_hidden_dims=(16, 32),
        latent_dim=LATENT,
        init_std=0.5,
        ppo=ppo,
    )


@pytest.fixture
def student_cfg() -> StudentCfg:
    """A [32, 32] student with a tiny temporal-convolution encoder over 8 frames (8 -> 4 -> 3 -> 2)."""
    return StudentCfg(
        actor_hidden_dims=(32, 32),
        history_length=HISTORY,
        tcn_channels=(8, 8, 8),
        tcn_kernel_sizes=(2, 2, 2),
        tcn_strides=(2, 1, 1),
        tcn_mlp_hidden_dims=(16,),
    )


@pytest.fixture
def distill_cfg() -> DistillCfg:
    """Imitation-only distillation (w_PPO = 0) with a fast fixed learning rate."""
    ppo = PpoCfg(
        num_learning_epochs=2, num_mini_batches=2, learning_rate=3e-3, schedule=PpoSchedule.fixed, entropy_coef=0.0
    )
    return DistillCfg(w_ppo_start=0.0, w_ppo_end=0.0, w_dist_start=1.0, w_dist_end=1.0, ppo=ppo)


@pytest.fixture
def runner_cfg() -> Callable[[dict], dict]:
    """Return a function that completes an rsl-rl train cfg with tiny runner settings."""

    def complete(entries: dict) -> dict:
        return {"num_steps_per_env": 4, "save_interval": 1000, "logger": "tensorboard", "multi_gpu": None} | entries

    return complete


@pytest.fixture
def teacher_ckpt(
    toy_env: VecEnv, teacher_cfg: TeacherCfg, groups: ObsGroupsCfg, runner_cfg: Callable[[dict], dict]
) -> dict:
    """A randomly initialised TeacherPPO checkpoint dict (``actor_state_dict``, ``critic_state_dict``, ...)."""
    torch.manual_seed(1)
    alg = TeacherPPO.construct_algorithm(
        toy_env.get_observations(), toy_env, runner_cfg(teacher_cfg.to_rsl_rl(groups)), "cpu"
    )
    return alg.save()


@pytest.fixture
def teacher_actor(
    toy_env: VecEnv, teacher_cfg: TeacherCfg, groups: ObsGroupsCfg, runner_cfg: Callable[[dict], dict]
) -> TeacherActor:
    """A randomly initialised TeacherActor, built by TeacherPPO's construct_algorithm."""
    alg = TeacherPPO.construct_algorithm(
        toy_env.get_observations(), toy_env, runner_cfg(teacher_cfg.to_rsl_rl(groups)), "cpu"
    )
    return alg.actor  # type: ignore[return-value]


@pytest.fixture
def new_student(
    toy_env: VecEnv,
    teacher_cfg: TeacherCfg,
    student_cfg: StudentCfg,
    distill_cfg: DistillCfg,
    groups: ObsGroupsCfg,
    runner_cfg: Callable[[dict], dict],
) -> Callable[[int], StudentPPO]:
    """Return a function that builds a fresh StudentPPO (no teacher loaded) from the typed cfgs with a given seed."""

    def build(seed: int) -> StudentPPO:
        torch.manual_seed(seed)
        cfg = runner_cfg(distill_cfg.to_rsl_rl(teacher_cfg, student_cfg, groups))
        return StudentPPO.construct_algorithm(toy_env.get_observations(), toy_env, cfg, "cpu")  # type: ignore[return-value]

    return build


@pytest.fixture
def student_alg(new_student: Callable[[int], StudentPPO], teacher_ckpt: dict) -> StudentPPO:
    """StudentPPO built by its construct_algorithm from the typed cfgs, with the teacher loaded."""
    alg = new_student(0)
    alg.load(teacher_ckpt, None, strict=True)
    return alg
