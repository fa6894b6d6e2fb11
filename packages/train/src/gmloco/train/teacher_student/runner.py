# SPDX-License-Identifier: Apache-2.0
"""Runner for GM-Loco distillation: rsl-rl's on-policy loop plus loading of the frozen teacher.

Selected with ``class_name="gmloco.train.teacher_student.runner:StudentRunner"``. It subclasses rsl-rl's
``OnPolicyRunner`` (not mjlab's, whose import pulls the whole simulator stack); like mjlab's runner it stores the
env's ``common_step_counter`` in each checkpoint when the env has one, so terrain curricula resume.
"""

from __future__ import annotations

import torch
from rsl_rl.env import VecEnv
from rsl_rl.runners import OnPolicyRunner

from gmloco.train.teacher_student.student_ppo import StudentPPO

__all__ = ["StudentRunner"]


class StudentRunner(OnPolicyRunner):
    """On-policy runner for :class:`StudentPPO` (DAgger + PPO) that loads a teacher checkpoint."""

    alg: StudentPPO

    def __init__(self, env: VecEnv, train_cfg: dict, log_dir: str | None = None, device: str = "cpu") -> None:
        """Build the runner; load ``train_cfg["teacher_checkpoint"]`` when it is set.

        Raises:
            TypeError: If the algorithm is not a :class:`StudentPPO`.
        """
        super().__init__(env, train_cfg, log_dir, device)
        if not isinstance(self.alg, StudentPPO):
            raise TypeError(f"StudentRunner needs StudentPPO, got {type(self.alg).__name__}.")
        if self.cfg.get("teacher_checkpoint"):
            self.load_teacher(self.cfg["teacher_checkpoint"])

    def load_teacher(self, path: str, map_location: str | None = None) -> None:
        """Load the teacher from a TeacherPPO checkpoint file (its env state is ignored)."""
        loaded = torch.load(path, map_location=map_location or self.device, weights_only=False)
        self.alg.load_teacher(loaded, strict=True)

    def learn(self, num_learning_iterations: int, init_at_random_ep_len: bool = False) -> None:
        """Distil for ``num_learning_iterations``; refuse to start without a loaded teacher.

        Raises:
            ValueError: If no teacher was loaded.
        """
        if not self.alg.teacher_loaded:
            raise ValueError("No teacher loaded: set train_cfg['teacher_checkpoint'] or call load_teacher(path).")
        super().learn(num_learning_iterations, init_at_random_ep_len)

    def save(self, path: str, infos: dict | None = None) -> None:
        """Save the checkpoint, with the env's ``common_step_counter`` when it has one."""
        counter = getattr(getattr(self.env, "unwrapped", self.env), "common_step_counter", None)
        if counter is not None:
            infos = {**(infos or {}), "env_state": {"common_step_counter": int(counter)}}
        super().save(path, infos)

    def load(
        self, path: str, load_cfg: dict | None = None, strict: bool = True, map_location: str | None = None
    ) -> dict:
        """Load a student (or teacher) checkpoint and restore the env's ``common_step_counter`` if saved."""
        infos = super().load(path, load_cfg, strict, map_location)
        env_state = (infos or {}).get("env_state")
        target = getattr(self.env, "unwrapped", self.env)
        if env_state is not None and hasattr(target, "common_step_counter"):
            target.common_step_counter = env_state["common_step_counter"]  # type: ignore[attr-defined]
        return infos
