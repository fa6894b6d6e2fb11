# SPDX-License-Identifier: Apache-2.0
"""The actor shape shared by teacher and student (``latent_actor.LatentActor``): input ``[o_t, z]`` and exports."""

from __future__ import annotations

from types import SimpleNamespace

import torch
from rsl_rl.env import VecEnv
from rsl_rl.models import MLPModel

from gmloco.train.teacher_student import StudentPPO, TeacherActor
from gmloco.train.teacher_student.latent_actor import LatentActor


def test_both_actors_read_o_t_then_the_latent_they_keep(
    toy_env: VecEnv, teacher_actor: TeacherActor, student_alg: StudentPPO, dims: SimpleNamespace
) -> None:
    """get_latent is rsl-rl's normalized o_t followed by z: the teacher's mu (eval mode), the student's z_hat."""
    teacher = teacher_actor
    obs = toy_env.get_observations()
    for actor in (teacher.eval(), student_alg.actor.eval()):
        assert isinstance(actor, LatentActor)
        assert actor.mlp[0].in_features == dims.obs_dim + dims.latent == actor._get_latent_dim()  # type: ignore[index]
        with torch.no_grad():
            latent = actor.get_latent(obs)
            o_t = MLPModel.get_latent(actor, obs)
        kept = actor.latent_mu if actor is teacher else actor.latent  # type: ignore[union-attr]
        assert latent.shape == (dims.num_envs, dims.obs_dim + dims.latent)
        torch.testing.assert_close(latent[:, : dims.obs_dim], o_t)
        torch.testing.assert_close(latent[:, dims.obs_dim :], kept)


def test_as_jit_and_as_onnx_hand_out_each_actors_export_copy(
    teacher_actor: TeacherActor, student_alg: StudentPPO
) -> None:
    """Teacher: one copy for both, output ``actions``; student: the ONNX copy adds ``latent`` and ``eta``."""
    student = student_alg.actor
    assert type(teacher_actor.as_jit()) is type(teacher_actor.as_onnx(verbose=False))
    assert teacher_actor.as_onnx(verbose=False).output_names == ["actions"]
    assert student.as_jit().output_names == ["actions"]
    assert student.as_onnx(verbose=False).output_names == ["actions", "latent", "eta"]
