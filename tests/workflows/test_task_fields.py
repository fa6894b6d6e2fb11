# SPDX-License-Identifier: Apache-2.0
"""The velocity task's fields by their path (``workflows/task_fields.py``): nested paths, range ends, bad input."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from omegaconf import DictConfig, OmegaConf

from workflows.stage_runner import PipelineConfigError
from workflows.task_fields import apply_task_fields, flat_paths


def test_flat_paths_of_a_nested_node() -> None:
    """Nested keys join with dots, digit keys stay path parts, lists and empty mappings are values."""
    node = OmegaConf.create({"material": {"mu_int": {"0": 0.2}, "packing": [0.5, 0.7]}, "episode_length_s": 3.0})
    assert flat_paths(node) == {"material.mu_int.0": 0.2, "material.packing": [0.5, 0.7], "episode_length_s": 3.0}
    assert flat_paths({}) == {} and flat_paths({"play": {}}) == {"play": {}}


def test_paths_set_nested_fields_and_range_ends() -> None:
    """Dotted paths reach nested dataclasses and tuple ends; ints become floats in float fields; input untouched."""
    from gmloco.train.config import GranularTaskCfg

    base = GranularTaskCfg()
    task = apply_task_fields(
        base,
        {
            "material.mu_int.0": 0.3,
            "robot_dr.push_velocity": 0,
            "terrain.floor.depth_range.1": 0.2,
            "terrain.floor.num_levels": 7,
            "command_curriculum": False,
        },
    )
    assert task.material.mu_int == (0.3, base.material.mu_int[1])
    assert task.robot_dr.push_velocity == 0.0 and isinstance(task.robot_dr.push_velocity, float)
    assert task.terrain.floor.depth_range == (0.0, 0.2) and task.terrain.floor.num_levels == 7
    assert task.command_curriculum is False
    assert base.material.mu_int == (0.2, 0.9) and base.command_curriculum is True
    assert apply_task_fields(base, {}) == base


def test_the_real_task_round_trips() -> None:
    """The mjlab task of an experiment comes back equal, field for field, when no path is set."""
    from gmloco.train import g1_granular_task

    task = g1_granular_task("rft3d", "deep")
    assert apply_task_fields(task, {}) == task
    changed = apply_task_fields(task, {"terrain.floor.num_levels": 7.0})
    assert changed.terrain.floor.num_levels == 7 and isinstance(changed.terrain.floor.num_levels, int)


def test_unknown_fields_and_empty_ranges_are_refused_by_name() -> None:
    """A typo names the key, its section and the section's valid keys; a crossing range (end) is refused."""
    from gmloco.train.config import GranularTaskCfg

    with pytest.raises(PipelineConfigError, match=r"no key 'mu_intt' in train_teacher\.task\.material; valid") as info:
        apply_task_fields(GranularTaskCfg(), {"material.mu_intt.0": 0.3})
    assert info.value.key == "train_teacher.task.material.mu_intt.0"
    with pytest.raises(PipelineConfigError, match=r"no key '2' in train_teacher\.task\.material\.mu_int; valid keys"):
        apply_task_fields(GranularTaskCfg(), {"material.mu_int.2": 0.3})
    with pytest.raises(PipelineConfigError, match=r"no key 'x' in train_teacher\.task\.episode_length_s; valid keys"):
        apply_task_fields(GranularTaskCfg(), {"episode_length_s.x": 0.3})
    with pytest.raises(PipelineConfigError, match="low > high"):
        apply_task_fields(GranularTaskCfg(), {"material.mu_int.0": 0.95})
    with pytest.raises(PipelineConfigError, match="low > high"):
        apply_task_fields(GranularTaskCfg(), {"material.mu_int": [0.5, 0.3]})


def test_the_command_line_sets_the_trained_task(compose: Callable[..., DictConfig]) -> None:
    """``+train_teacher.task.<path>=`` reaches the task the train stage builds (the held-out cut kept)."""
    from workflows.policy_training import task_cfg

    cfg = compose(
        "+exp=gm_loco",
        "+train_teacher.task.robot_dr.push_velocity=0.25",
        "+train_teacher.task.terrain.floor.num_levels=4",
        "+train_teacher.task.material.packing.0=0.55",
    )
    plain, task = task_cfg(compose("+exp=gm_loco").train_teacher), task_cfg(cfg.train_teacher)
    assert task.robot_dr.push_velocity == 0.25 and task.terrain.floor.num_levels == 4
    assert task.material.packing == (0.55, plain.material.packing[1])
    assert task.material.held_out_mu_int == plain.material.held_out_mu_int is not None
