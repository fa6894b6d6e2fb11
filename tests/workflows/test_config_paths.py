# SPDX-License-Identifier: Apache-2.0
"""One dotted-path language for config sections and package dataclasses (``workflows/config_paths.py``)."""

from __future__ import annotations

from dataclasses import dataclass, field

from omegaconf import OmegaConf

from workflows.config_paths import dataclass_from_node, dataclass_node, path_problem


@dataclass(frozen=True)
class _RangeCfg:
    """A range end pair and a count, like the task's DR ranges."""

    span: tuple[float, float] = (0.2, 0.9)
    """A range [low, high]."""
    count: int = 3
    """A whole number."""


@dataclass(frozen=True)
class _OuterCfg:
    """A dataclass with a nested one, as ``GranularTaskCfg`` holds ``MaterialRangeCfg``."""

    inner: _RangeCfg = field(default_factory=_RangeCfg)
    """The nested section."""
    weights: dict[str, float] = field(default_factory=lambda: {"a": 1.0})
    """A dict of floats."""


def test_path_problem_names_the_missing_part_and_the_valid_keys() -> None:
    """A path that exists has no problem; a typo names its section and that section's keys (list indices too)."""
    node = dataclass_node(_OuterCfg())
    assert path_problem(node, "inner.span.1") is None
    assert path_problem(node, "inner.spam", "task.") == "no key 'spam' in task.inner; valid keys: span, count."
    assert path_problem(node, "inner.span.2") == "no key '2' in inner.span; valid keys: 0, 1."
    assert path_problem(node, "nope") == "no key 'nope' in the config; valid keys: inner, weights."
    assert "(none: it is a value" in str(path_problem(node, "inner.count.x"))


def test_dataclass_round_trip_keeps_types_and_sets_paths() -> None:
    """Unchanged node: the same dataclass; ``OmegaConf.update`` paths come back with the field's type."""
    base = _OuterCfg()
    node = dataclass_node(base)
    assert dataclass_from_node(base, node) == base
    OmegaConf.update(node, "inner.span.0", 0, merge=True)  # an int into a float tuple
    OmegaConf.update(node, "inner.count", 5.0, merge=True)  # a whole float into an int field
    OmegaConf.update(node, "weights.a", 2, merge=True)
    new = dataclass_from_node(base, node)
    assert new.inner.span == (0.0, 0.9) and isinstance(new.inner.span, tuple) and isinstance(new.inner.span[0], float)
    assert new.inner.count == 5 and isinstance(new.inner.count, int)
    assert new.weights == {"a": 2.0} and base.inner.span == (0.2, 0.9)
