# SPDX-License-Identifier: Apache-2.0
"""GM-Loco teacher-student learning as rsl-rl plug-ins (Kamohara et al., arXiv 2603.13707, Sec. IV).

* Teacher: :class:`TeacherActor` (actor over ``[o_t, z_t]``, VAE terrain encoder, eta decoder) trained by
  :class:`TeacherPPO` (L_PPO + eta reconstruction + beta * KL), with rsl-rl's ``MLPModel`` as asymmetric critic.
* Student: :class:`StudentActor` (three 1-D convolutions + MLP over the N-step history) trained by
  :class:`StudentPPO` (DAgger + weighted PPO, frozen teacher) under :class:`StudentRunner`.
* Configs: :class:`TeacherCfg`, :class:`StudentCfg`, :class:`DistillCfg`, :class:`ObsGroupsCfg`, :class:`PpoCfg`.
* Export: :mod:`~gmloco.train.teacher_student.export_student` rebuilds a trained student on the env, exports it
  with its deploy metadata (:mod:`gmloco.train.tasks.g1_granular.policy_metadata`) and checks it.
* Held-out materials: :class:`HeldOutRegionCfg` (a (rho_c, mu_int) rectangle the DR never draws, see
  :func:`redraw_outside`) and :func:`r2_score` for the decoded eta.

The exports are resolved lazily (PEP 562): ``gmloco.train.teacher_student.config`` (pure data, read by the
pipeline's config schemas) imports without torch or rsl-rl.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gmloco.train.lazy_exports import lazy_exports
from gmloco.train.teacher_student import config  # pure data: no torch, no rsl-rl

if TYPE_CHECKING:
    from gmloco.train.teacher_student.config import (
        CRITIC_CLASS,
        DEFAULT_HISTORY_LENGTH,
        STUDENT_ACTOR_CLASS,
        STUDENT_PPO_CLASS,
        STUDENT_RUNNER_CLASS,
        TEACHER_ACTOR_CLASS,
        TEACHER_PPO_CLASS,
        DistillCfg,
        ObsGroupsCfg,
        PpoCfg,
        PpoOptimizer,
        PpoSchedule,
        StudentCfg,
        TeacherCfg,
        student_train_entries,
    )
    from gmloco.train.teacher_student.curriculum import LinearRamp
    from gmloco.train.teacher_student.heldout import DEFAULT_HELD_OUT, HeldOutRegionCfg, r2_score, redraw_outside
    from gmloco.train.teacher_student.runner import StudentRunner
    from gmloco.train.teacher_student.student import StudentActor
    from gmloco.train.teacher_student.student_ppo import StudentPPO
    from gmloco.train.teacher_student.teacher import TeacherActor
    from gmloco.train.teacher_student.teacher_ppo import TeacherPPO

_CONFIG = "gmloco.train.teacher_student.config"
_EXPORTS: dict[str, str] = {
    **dict.fromkeys(config.__all__, _CONFIG),
    "LinearRamp": "gmloco.train.teacher_student.curriculum",
    "DEFAULT_HELD_OUT": "gmloco.train.teacher_student.heldout",
    "HeldOutRegionCfg": "gmloco.train.teacher_student.heldout",
    "r2_score": "gmloco.train.teacher_student.heldout",
    "redraw_outside": "gmloco.train.teacher_student.heldout",
    "StudentRunner": "gmloco.train.teacher_student.runner",
    "StudentActor": "gmloco.train.teacher_student.student",
    "StudentPPO": "gmloco.train.teacher_student.student_ppo",
    "TeacherActor": "gmloco.train.teacher_student.teacher",
    "TeacherPPO": "gmloco.train.teacher_student.teacher_ppo",
}
"""Public name -> the module that defines it."""

__all__ = [
    "CRITIC_CLASS",
    "DEFAULT_HELD_OUT",
    "DEFAULT_HISTORY_LENGTH",
    "STUDENT_ACTOR_CLASS",
    "STUDENT_PPO_CLASS",
    "STUDENT_RUNNER_CLASS",
    "TEACHER_ACTOR_CLASS",
    "TEACHER_PPO_CLASS",
    "DistillCfg",
    "HeldOutRegionCfg",
    "LinearRamp",
    "ObsGroupsCfg",
    "PpoCfg",
    "PpoOptimizer",
    "PpoSchedule",
    "StudentActor",
    "StudentCfg",
    "StudentPPO",
    "StudentRunner",
    "TeacherActor",
    "TeacherCfg",
    "TeacherPPO",
    "r2_score",
    "redraw_outside",
    "student_train_entries",
]


__getattr__, __dir__ = lazy_exports(globals(), _EXPORTS)
