# SPDX-License-Identifier: Apache-2.0
"""Lazily resolved package exports (PEP 562), shared by the packages that keep heavy imports off start-up."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(
    namespace: dict[str, Any], exports: Mapping[str, str]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """Return a package's ``(__getattr__, __dir__)`` resolving ``exports`` (public name -> defining module).

    ``namespace`` is the package's ``globals()``: a name is imported on first access and cached there. An unknown
    name raises AttributeError, which lets ``from package import submodule`` fall back to importing the submodule.
    """

    def getattr_(name: str) -> Any:
        """Import the module defining the public ``name`` on first access and cache the value in the package."""
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {namespace['__name__']!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        namespace[name] = value
        return value

    def dir_() -> list[str]:
        """List the package's attributes, including the not-yet-imported public names."""
        return sorted({*namespace, *namespace.get("__all__", ())})

    return getattr_, dir_
