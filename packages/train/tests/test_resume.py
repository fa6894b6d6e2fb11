# SPDX-License-Identifier: Apache-2.0
"""Resume checks: a changed config is refused naming its keys; a corrupt checkpoint is named and skipped."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import torch

from gmloco.train.resume import (
    RUN_CFG_FILE,
    ResumeError,
    check_resume_cfg,
    config_differences,
    resumable_checkpoint,
)


def _cfg(actor: str = "gmloco.train.teacher_student.teacher:TeacherActor", **task: Any) -> dict[str, Any]:
    """A run config as JSON: a task, sizes and the algorithm's actor class."""
    base_task = {"contact_model": "rft3d", "foot_clearance": "touchdown", "reward_weights": {"foot_clearance_l2": -50}}
    return {
        "task": base_task | task,
        "num_envs": 4096,
        "num_steps_per_env": 24,
        "hidden_dims": [512, 256, 128],
        "seed": 42,
        "history_length": 50,
        "rsl_rl_overrides": {"actor": {"class_name": actor, "latent_dim": 16}},
        "max_iterations": 6000,
    }


def test_differences_name_leaf_keys() -> None:
    """Nested dicts compare leaf by leaf; an absent key reads ``absent``."""
    saved = {"a": {"b": 1, "c": [1, 2]}, "d": "x"}
    current = {"a": {"b": 2, "c": [1, 2], "e": True}, "d": "x"}
    assert config_differences(saved, current) == ["a.b: 1 -> 2", "a.e: absent -> true"]
    assert config_differences(saved, saved) == []


def test_first_call_records_and_same_config_resumes(tmp_path: Path) -> None:
    """The first call writes train_cfg.json; a call with the same invariants (more iterations) passes."""
    check_resume_cfg(tmp_path, _cfg())
    assert json.loads((tmp_path / "train_cfg.json").read_text())["seed"] == 42
    check_resume_cfg(tmp_path, _cfg() | {"max_iterations": 9000})
    assert json.loads((tmp_path / "train_cfg.json").read_text())["max_iterations"] == 9000


def test_changed_task_is_refused_with_the_differing_keys(tmp_path: Path) -> None:
    """A chunk with another clearance mode and weight is refused, the run's train_cfg.json untouched."""
    check_resume_cfg(tmp_path, _cfg())
    before = (tmp_path / "train_cfg.json").read_text()
    changed = _cfg(foot_clearance="sinkage", reward_weights={"foot_clearance_l2": -2})
    with pytest.raises(ResumeError) as err:
        check_resume_cfg(tmp_path, changed)
    message = str(err.value)
    assert 'task.foot_clearance: "touchdown" -> "sinkage"' in message
    assert "task.reward_weights.foot_clearance_l2: -50 -> -2" in message
    assert "another run_dir" in message
    assert (tmp_path / "train_cfg.json").read_text() == before


def test_other_experiment_is_named(tmp_path: Path) -> None:
    """A student config pointed at a teacher's run directory names both algorithms."""
    check_resume_cfg(tmp_path, _cfg())
    with pytest.raises(ResumeError, match="holds a TeacherActor run; this config trains StudentActor"):
        check_resume_cfg(tmp_path, _cfg(actor="gmloco.train.teacher_student.student:StudentActor"))


def test_allowed_keys_may_change(tmp_path: Path) -> None:
    """``allow_changed`` accepts named keys and prefixes, and only those."""
    check_resume_cfg(tmp_path, _cfg())
    check_resume_cfg(tmp_path, _cfg(reward_weights={"foot_clearance_l2": -2}), allowed=["task.reward_weights"])
    with pytest.raises(ResumeError, match=r"task\.foot_clearance"):
        check_resume_cfg(tmp_path, _cfg(foot_clearance="sinkage"), allowed=["task.reward_weights"])
    # The record now holds weight -2 (the last accepted call's), so -50 is a change too.
    with pytest.raises(ResumeError, match=r"foot_clearance_l2: -2 -> -50"):
        check_resume_cfg(tmp_path, _cfg(foot_clearance="sinkage"), allowed=["task.foot_clearance"])
    check_resume_cfg(tmp_path, _cfg(foot_clearance="sinkage"), allowed=["task.foot_clearance", "task.reward_weights"])


def _save(path: Path, iteration: int) -> None:
    """A minimal rsl-rl checkpoint."""
    torch.save({"iter": iteration, "actor_state_dict": {"w": torch.zeros(2)}}, path)


def test_corrupt_newest_checkpoint_is_named_and_the_previous_used(tmp_path: Path) -> None:
    """model_100.pt truncated: model_50.pt is returned, the broken file kept as model_100.pt.corrupt."""
    _save(tmp_path / "model_50.pt", 50)
    _save(tmp_path / "model_100.pt", 100)
    data = (tmp_path / "model_100.pt").read_bytes()
    (tmp_path / "model_100.pt").write_bytes(data[: len(data) // 2])
    path, skipped = resumable_checkpoint(tmp_path)
    assert path == tmp_path / "model_50.pt"
    assert len(skipped) == 1 and "model_100.pt is corrupt" in skipped[0]
    assert (tmp_path / "model_100.pt.corrupt").exists() and not (tmp_path / "model_100.pt").exists()
    assert resumable_checkpoint(tmp_path) == (tmp_path / "model_50.pt", [])


def test_no_readable_checkpoint_is_refused(tmp_path: Path) -> None:
    """Checkpoints that all fail to load are an error (not a silent fresh start); no checkpoint at all is None."""
    assert resumable_checkpoint(tmp_path) == (None, [])
    (tmp_path / "model_10.pt").write_bytes(b"not a checkpoint")
    torch.save({"weights": 1}, tmp_path / "model_5.pt")
    with pytest.raises(ResumeError, match=r"every checkpoint .* is unreadable.*no 'iter' entry"):
        resumable_checkpoint(tmp_path)


def test_field_added_later_at_its_default_does_not_block(tmp_path: Path) -> None:
    """A saved config without a newer field resumes while that field keeps its default, and refuses otherwise."""
    saved = {"task": {"contact_model": "rft3d"}, "seed": 1}
    (tmp_path / RUN_CFG_FILE).write_text(json.dumps(saved))
    defaults = {"task": {"contact_model": "rft3d", "new_term": None}, "seed": 42}
    check_resume_cfg(tmp_path, {"task": {"contact_model": "rft3d", "new_term": None}, "seed": 1}, defaults=defaults)
    (tmp_path / RUN_CFG_FILE).write_text(json.dumps(saved))
    with pytest.raises(ResumeError, match=r"task\.new_term: absent -> 0\.5"):
        check_resume_cfg(tmp_path, {"task": {"contact_model": "rft3d", "new_term": 0.5}, "seed": 1}, defaults=defaults)
