# SPDX-License-Identifier: Apache-2.0
"""Student checkpoints with a detached teacher: exact round trip, and refusals when the teacher file is wrong."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
import torch

from gmloco.train.teacher_student import StudentPPO
from gmloco.train.teacher_student.checkpoint_teacher import (
    TEACHER_SOURCE_KEY,
    attach_teacher,
    detach_teacher,
    state_digest,
)


@pytest.fixture
def saved(student_alg: StudentPPO, teacher_ckpt: dict, tmp_path: Path) -> tuple[dict, Path]:
    """A student checkpoint dict and the teacher checkpoint file it was distilled from."""
    path = tmp_path / "teacher.pt"
    torch.save(teacher_ckpt, path)
    return student_alg.save(), path


def test_detached_student_loads_back_exactly(
    saved: tuple[dict, Path], new_student: Callable[[int], StudentPPO]
) -> None:
    """Detach, load into a fresh StudentPPO: student and teacher tensors equal the full checkpoint's."""
    full, teacher_path = saved
    slim = detach_teacher(full, teacher_path)
    assert "teacher_state_dict" not in slim and slim[TEACHER_SOURCE_KEY] == str(teacher_path)
    fresh = new_student(3)
    assert fresh.load(slim, None, strict=True) is True
    assert fresh.teacher_loaded
    assert state_digest(fresh.teacher.state_dict()) == state_digest(full["teacher_state_dict"])
    assert state_digest(fresh.actor.state_dict()) == state_digest(full["actor_state_dict"])


def test_detach_refuses_a_teacher_file_that_is_not_the_students_teacher(saved: tuple[dict, Path]) -> None:
    """The embedded teacher is compared with the file before it is dropped."""
    full, teacher_path = saved
    other = torch.load(teacher_path, weights_only=False)
    key = next(iter(other["actor_state_dict"]))
    other["actor_state_dict"][key] = other["actor_state_dict"][key] + 1.0
    torch.save(other, teacher_path)
    with pytest.raises(ValueError, match="differs from"):
        detach_teacher(full, teacher_path)


def test_attach_refuses_a_teacher_file_changed_after_detaching(saved: tuple[dict, Path]) -> None:
    """A teacher file edited after the student was saved no longer matches the digest."""
    full, teacher_path = saved
    slim = detach_teacher(full, teacher_path)
    changed = torch.load(teacher_path, weights_only=False)
    key = next(iter(changed["actor_state_dict"]))
    changed["actor_state_dict"][key] = changed["actor_state_dict"][key] + 1.0
    torch.save(changed, teacher_path)
    with pytest.raises(ValueError, match="digest mismatch"):
        attach_teacher(slim)


def test_attach_names_a_missing_teacher_file(saved: tuple[dict, Path]) -> None:
    """A missing teacher file is reported by its path, with what to do."""
    full, teacher_path = saved
    slim = detach_teacher(full, teacher_path)
    teacher_path.unlink()
    with pytest.raises(FileNotFoundError, match="repository root"):
        attach_teacher(slim)


def test_full_and_teacher_checkpoints_pass_through_attach(saved: tuple[dict, Path], teacher_ckpt: dict) -> None:
    """Nothing detached, nothing to do: the same object comes back."""
    full, _ = saved
    assert attach_teacher(full) is full and attach_teacher(teacher_ckpt) is teacher_ckpt


def test_state_digest_ignores_order_and_sees_one_value() -> None:
    """Same tensors in another order: same digest; one element changed: another digest."""
    a = {"x": torch.arange(3.0), "y": torch.ones(2, 2)}
    b = {"y": torch.ones(2, 2), "x": torch.arange(3.0)}
    assert state_digest(a) == state_digest(b)
    b["x"] = torch.tensor([0.0, 1.0, 2.5])
    assert state_digest(a) != state_digest(b)
