# SPDX-License-Identifier: Apache-2.0
"""The export copy shared by teacher and student (``actor_export.LatentActorExport``): inputs and copied weights."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import torch

from gmloco.train.teacher_student import StudentPPO, TeacherActor


def test_both_wrappers_name_and_shape_their_inputs_and_copy_the_encoder_normalizer(
    teacher_actor: TeacherActor, student_alg: StudentPPO, dims: SimpleNamespace
) -> None:
    """Teacher: (obs, encoder_obs [enc_dim]); student: (obs, history [N, D]); each holds a copy of its normalizer."""
    teacher = teacher_actor
    student = student_alg.actor
    cases: tuple[tuple[Any, Any, str, tuple[int, ...]], ...] = (
        (teacher, teacher.encoder_normalizer, "encoder_obs", (teacher.encoder_obs_dim,)),  # type: ignore[attr-defined]
        (student, student.history_normalizer, "history", (dims.history, student.history_frame_dim)),  # type: ignore[attr-defined]
    )
    for actor, normalizer, name, shape in cases:
        wrappers: tuple[Any, ...] = (actor.as_jit(), actor.as_onnx(verbose=False))  # type: ignore[operator]
        for wrapper in wrappers:
            assert wrapper.input_names == ["obs", name]
            obs, enc = wrapper.get_dummy_inputs()
            assert tuple(obs.shape) == (1, dims.obs_dim) and tuple(enc.shape) == (1, *shape)
            assert wrapper.encoder_normalizer is not normalizer
            copied, original = wrapper.encoder_normalizer.state_dict(), normalizer.state_dict()
            assert list(copied) == list(original) and len(original) > 0
            for key, value in original.items():
                torch.testing.assert_close(copied[key], value)
