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
"""

from gmloco.train.teacher_student.config import (
    CRITIC_CLASS,
    STUDENT_ACTOR_CLASS,
    STUDENT_PPO_CLASS,
    STUDENT_RUNNER_CLASS,
    TEACHER_ACTOR_CLASS,
    TEACHER_PPO_CLASS,
    DistillCfg,
    ObsGroupsCfg,
    PpoCfg,
    StudentCfg,
    TeacherCfg,
    student_train_entries,
)
from gmloco.train.teacher_student.curriculum import LinearRamp
from gmloco.train.teacher_student.heldout import DEFAULT_HELD_OUT, HeldOutRegionCfg, r2_score, redraw_outside
from gmloco.train.teacher_student.runner import StudentRunner
from gmloco.train.teacher_student.student import DEFAULT_HISTORY_LENGTH, StudentActor
from gmloco.train.teacher_student.student_ppo import StudentPPO
from gmloco.train.teacher_student.teacher import TeacherActor
from gmloco.train.teacher_student.teacher_ppo import TeacherPPO

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
