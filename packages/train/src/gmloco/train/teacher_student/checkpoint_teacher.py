# SPDX-License-Identifier: Apache-2.0
"""Student checkpoints that name their frozen teacher instead of carrying it.

A distillation checkpoint holds the frozen teacher (``teacher_state_dict``), whose history encoder makes it three
quarters of the file. The teacher is committed once as its own checkpoint (``artifacts/<teacher run>/``); a
committed student checkpoint can point at that file instead: :func:`detach_teacher` drops the embedded copy after
checking it equals the file's, and records the path (``teacher_source``) and a digest of the tensors
(``teacher_digest``). :func:`attach_teacher`, called by ``StudentPPO.load``, puts the teacher back and refuses a
teacher file whose tensors differ from the digest, so a detached checkpoint resumes, evaluates and exports exactly
as the full one.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import torch

__all__ = ["TEACHER_DIGEST_KEY", "TEACHER_SOURCE_KEY", "attach_teacher", "detach_teacher", "state_digest"]

TEACHER_SOURCE_KEY = "teacher_source"
"""Checkpoint key: path of the TeacherPPO checkpoint whose ``actor_state_dict`` is the frozen teacher."""
TEACHER_DIGEST_KEY = "teacher_digest"
"""Checkpoint key: :func:`state_digest` of that teacher."""


def state_digest(state: Mapping[str, Any]) -> str:
    """SHA-256 over a state dict's names, dtypes, shapes and values (independent of the device it lives on)."""
    h = hashlib.sha256()
    for name in sorted(state):
        value = state[name]
        h.update(name.encode())
        if torch.is_tensor(value):
            t = value.detach().cpu().contiguous()
            h.update(f"{t.dtype}{tuple(t.shape)}".encode())
            h.update(t.reshape(-1).view(torch.uint8).numpy().tobytes() if t.numel() else b"")
        else:
            h.update(repr(value).encode())
    return h.hexdigest()


def _teacher_state(path: str | Path) -> dict[str, Any]:
    """The frozen teacher of a TeacherPPO checkpoint file (its ``actor_state_dict``)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(
            f"teacher checkpoint {path} not found: a detached student checkpoint loads its teacher from this path "
            "(relative paths from the repository root); run from there or restore the file"
        )
    loaded = torch.load(path, map_location="cpu", weights_only=False)
    if "actor_state_dict" not in loaded or "teacher_state_dict" in loaded:
        raise ValueError(f"{path} is not a TeacherPPO checkpoint (needs actor_state_dict, no teacher_state_dict)")
    return loaded["actor_state_dict"]


def detach_teacher(student: Mapping[str, Any], teacher_path: str | Path) -> dict[str, Any]:
    """Return the student checkpoint without its teacher, pointing at ``teacher_path`` instead.

    Raises:
        ValueError: If ``student`` carries no teacher, or its teacher differs from the one in ``teacher_path``.
    """
    if "teacher_state_dict" not in student:
        raise ValueError("not a student checkpoint with an embedded teacher (no teacher_state_dict)")
    digest = state_digest(student["teacher_state_dict"])
    if state_digest(_teacher_state(teacher_path)) != digest:
        raise ValueError(
            f"the student's frozen teacher differs from {teacher_path}: pass the teacher checkpoint it was distilled "
            "from (the run's --teacher-checkpoint)"
        )
    out = {k: v for k, v in student.items() if k != "teacher_state_dict"}
    out[TEACHER_SOURCE_KEY] = str(teacher_path)
    out[TEACHER_DIGEST_KEY] = digest
    return out


def attach_teacher(loaded: Mapping[str, Any]) -> Mapping[str, Any]:
    """Return ``loaded`` with its teacher put back if it was detached (unchanged otherwise).

    Raises:
        FileNotFoundError: If the named teacher file is missing.
        ValueError: If the teacher file's tensors differ from the recorded digest.
    """
    if "teacher_state_dict" in loaded or TEACHER_SOURCE_KEY not in loaded:
        return loaded
    teacher = _teacher_state(loaded[TEACHER_SOURCE_KEY])
    if state_digest(teacher) != loaded[TEACHER_DIGEST_KEY]:
        raise ValueError(
            f"teacher checkpoint {loaded[TEACHER_SOURCE_KEY]} changed since this student was saved (digest "
            "mismatch): restore the teacher file the student was distilled from"
        )
    return {**loaded, "teacher_state_dict": teacher}
