# SPDX-License-Identifier: Apache-2.0
"""One dotted-path language (OmegaConf's, ``material.mu_int.0``) for config sections and package dataclasses.

A composed config is addressed as Hydra addresses it; a package dataclass (``gmloco.train.GranularTaskCfg``) is
turned into an OmegaConf node, set with ``OmegaConf.update`` and turned back, so the same paths reach both.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

from omegaconf import Container, DictConfig, ListConfig, OmegaConf

__all__ = ["dataclass_from_node", "dataclass_node", "path_problem"]

T = TypeVar("T")

_MISSING = object()
"""Marks a path ``OmegaConf.select`` does not find."""


def _keys(section: Any) -> list[str]:
    """The keys of an OmegaConf section (indices of a list), none for a value."""
    if isinstance(section, DictConfig):
        return [str(k) for k in section]
    if isinstance(section, ListConfig):
        return [str(i) for i in range(len(section))]
    return []


def path_problem(node: Container, path: str, prefix: str = "") -> str | None:
    """Why ``path`` names no key of ``node``: its first missing part and the valid keys of that section; None if it does.

    ``prefix`` (``task.``) is put before the section's path in the message.
    """
    if OmegaConf.select(node, path, default=_MISSING) is not _MISSING:
        return None
    section: Any = node
    where = prefix.rstrip(".")
    for part in path.split("."):
        child = OmegaConf.select(section, part, default=_MISSING) if isinstance(section, Container) else _MISSING
        if child is _MISSING:
            keys = ", ".join(_keys(section)) or "(none: it is a value, not a section)"
            return f"no key '{part}' in {where or 'the config'}; valid keys: {keys}."
        section, where = child, f"{where}.{part}" if where else part
    return None


def dataclass_node(obj: Any) -> DictConfig:
    """An untyped OmegaConf node holding the fields of the dataclass instance ``obj`` (tuples become lists)."""
    return OmegaConf.create(dataclasses.asdict(obj))


def dataclass_from_node(template: T, node: DictConfig) -> T:
    """Return ``template`` (a dataclass instance) with the values of ``node``, each of the type it replaces."""
    return _rebuild(template, OmegaConf.to_container(node, resolve=True))


def _rebuild(template: Any, value: Any) -> Any:
    """``value`` shaped like ``template``: dataclasses, tuples and lists rebuilt field by field."""
    if dataclasses.is_dataclass(template) and not isinstance(template, type):
        names = [f.name for f in dataclasses.fields(template) if f.init]
        return dataclasses.replace(template, **{n: _rebuild(getattr(template, n), value[n]) for n in names})
    if isinstance(template, tuple | list) and isinstance(value, list | tuple) and len(template) == len(value):
        return type(template)(_rebuild(t, v) for t, v in zip(template, value, strict=True))
    if isinstance(template, dict) and isinstance(value, dict):
        return {k: _rebuild(template.get(k), v) for k, v in value.items()}
    return _coerce(template, value)


def _coerce(current: Any, value: Any) -> Any:
    """Give ``value`` the type of the field it replaces (float fields accept ints, tuples accept lists)."""
    if isinstance(current, bool) or current is None:
        return value
    if isinstance(current, float) and isinstance(value, int | float):
        return float(value)
    if isinstance(current, int) and isinstance(value, float) and value.is_integer():
        return int(value)
    if isinstance(current, tuple) and isinstance(value, list | tuple):
        return tuple(value)
    return value
