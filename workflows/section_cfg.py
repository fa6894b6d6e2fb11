# SPDX-License-Identifier: Apache-2.0
"""Turn a composed stage section into the package dataclass its schema extends."""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

from omegaconf import DictConfig, OmegaConf

__all__ = ["field_values", "section_as"]

T = TypeVar("T")


def _tuples(value: Any) -> Any:
    """``value`` with its lists, also those inside nested dataclasses, turned into tuples."""
    if isinstance(value, list):
        return tuple(value)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return dataclasses.replace(value, **{k: _tuples(v) for k, v in field_values(value).items()})
    return value


def field_values(obj: Any) -> dict[str, Any]:
    """The fields of a dataclass instance by name, values as they are (nested dataclasses kept)."""
    return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}


def section_as(cls: type[T], section: DictConfig, **changes: Any) -> T:
    """Return ``cls`` built from the fields of ``section`` that ``cls`` declares, then ``changes``.

    The section's schema extends ``cls`` with stage fields (``out_dir``, ``num_envs``, ...), which are left out.
    OmegaConf holds tuples as lists; they become tuples again, as the package dataclasses write them.
    """
    obj = OmegaConf.to_object(section)
    assert isinstance(obj, cls), f"section of type {type(obj).__name__} is not a {cls.__name__}"
    values = {f.name: _tuples(getattr(obj, f.name)) for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    return cls(**(values | changes))
