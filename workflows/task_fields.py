# SPDX-License-Identifier: Apache-2.0
"""The velocity task's fields by their path: ``train_teacher.task.<path>`` in a config, a command line or a sweep.

``gmloco.train.GranularTaskCfg`` (domain randomization, curricula, rewards, the sand bed) is built by the train
stage from the section's names (contact model, terrain, material); ``train_teacher.task`` then sets any field of it
by its path, nested as Hydra writes it: ``+train_teacher.task.robot_dr.push_velocity=1.0``, or one end of a range
with a digit part, ``+train_teacher.task.material.mu_int.0=0.2`` (``docs/sweeps.md``). Each path is checked
against the task (the message lists the valid keys where it went wrong) and no range may end up empty.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from omegaconf import DictConfig, ListConfig, OmegaConf

from workflows.config_paths import dataclass_from_node, dataclass_node, path_problem
from workflows.stage_runner import PipelineConfigError

__all__ = ["TASK_SECTION", "apply_task_fields", "flat_paths"]

TASK_SECTION = "train_teacher.task"
"""Config path of the task's fields."""


def flat_paths(node: Any, prefix: str = "") -> dict[str, Any]:
    """``{"a.b.0": v}`` of a nested mapping (``{"a": {"b": {"0": v}}}``); lists and values are leaves."""
    if isinstance(node, DictConfig):
        node = OmegaConf.to_container(node, resolve=True)
    if not isinstance(node, Mapping):
        return {prefix: node}
    out: dict[str, Any] = {}
    for key, value in node.items():
        path = f"{prefix}.{key}" if prefix else str(key)
        out |= flat_paths(value, path) if isinstance(value, Mapping) and value else {path: value}
    return out


def _bad(key: str, message: str) -> PipelineConfigError:
    """An input error naming ``key`` (one paragraph, exit code 2)."""
    return PipelineConfigError(key, f"{key}: {message}")


def _check_ranges(node: DictConfig, paths: list[str], where: str) -> None:
    """Raise when a range one of ``paths`` set (or one of its ends) has low > high."""
    for path in paths:
        parent, _, end = path.rpartition(".")
        pair = OmegaConf.select(node, parent if end.isdigit() else path)
        if isinstance(pair, ListConfig) and len(pair) == 2 and pair[0] > pair[1]:
            raise _bad(f"{where}.{path}", f"makes the range {list(pair)} empty (low > high); narrow its bounds.")


def apply_task_fields(task: Any, fields: Mapping[str, Any], where: str = TASK_SECTION) -> Any:
    """Return ``task`` (a ``GranularTaskCfg``) with each ``path: value`` of ``fields`` set; range ends are checked.

    Paths are OmegaConf's, relative to the task (``material.mu_int.0``). An unknown path or an empty range raises a
    :class:`PipelineConfigError` naming ``<where>.<path>``.
    """
    if not fields:
        return task
    node = dataclass_node(task)
    for path, value in fields.items():
        if (problem := path_problem(node, path, f"{where}.")) is not None:
            raise _bad(f"{where}.{path}", problem)
        OmegaConf.update(node, path, value, merge=True)
    _check_ranges(node, list(fields), where)
    return dataclass_from_node(task, node)
