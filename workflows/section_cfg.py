# SPDX-License-Identifier: Apache-2.0
"""Turn a composed stage section into the package dataclass its schema extends."""

from __future__ import annotations

from dataclasses import fields
from typing import Any, TypeVar

from omegaconf import DictConfig, OmegaConf

__all__ = ["section_as"]

T = TypeVar("T")


def section_as(cls: type[T], section: DictConfig, **changes: Any) -> T:
    """Return ``cls`` built from the fields of ``section`` that ``cls`` declares, then ``changes``.

    The section's schema extends ``cls`` with stage fields (``out_dir``, ``num_envs``, ...), which are left out.
    OmegaConf holds tuples as lists; the top-level lists become tuples again, as the package dataclasses write
    them.
    """
    obj = OmegaConf.to_object(section)
    assert isinstance(obj, cls), f"section of type {type(obj).__name__} is not a {cls.__name__}"
    values = {f.name: getattr(obj, f.name) for f in fields(cls)}  # type: ignore[arg-type]
    values = {k: tuple(v) if isinstance(v, list) else v for k, v in values.items()}
    return cls(**(values | changes))
