# SPDX-License-Identifier: Apache-2.0
"""Valid ranges of the numeric config fields, declared next to each field and checked when a config is composed.

A schema field declares its range through :func:`ranged` (a scalar: ``num_envs: int = ranged(4096, ge=1)``) or
:func:`each` (every element of a list: ``field(default_factory=..., metadata=each(gt=0))``). A package dataclass
used as a schema, which cannot import this module, writes the bounds themselves in its ``metadata``
(``field(default=0.99, metadata={"ge": 0, "le": 1})``); :func:`range_of` reads both forms. :func:`range_problem` walks a composed config along its schema
dataclass and returns the first value outside its range as ``(dotted key, message)``; the entry point turns it
into one exit-2 paragraph before anything runs.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from dataclasses import dataclass, field
from typing import Any

from omegaconf import DictConfig, ListConfig, OmegaConf

__all__ = ["BOUND_KEYS", "RANGE_KEY", "Range", "each", "range_of", "range_problem", "ranged"]

RANGE_KEY = "gmloco_range"
"""Key of a field's :class:`Range` in its dataclass ``metadata``."""
BOUND_KEYS = ("ge", "gt", "le", "lt", "also")
"""Plain ``metadata`` keys of a package dataclass field's bounds (same meaning as :class:`Range`'s fields)."""


def _num(value: float) -> str:
    """A bound as written: whole numbers without a fraction (``4294967295``, not ``4.29e+09``)."""
    return str(int(value)) if float(value).is_integer() else f"{value:g}"


@dataclass(frozen=True)
class Range:
    """Closed or open bounds of a number; ``also`` lists values accepted outside them (e.g. 0 = unbounded)."""

    ge: float | None = None
    """Inclusive lower bound."""
    gt: float | None = None
    """Exclusive lower bound."""
    le: float | None = None
    """Inclusive upper bound."""
    lt: float | None = None
    """Exclusive upper bound."""
    integer: bool = False
    """The value must be a whole number (the field is an ``int``)."""
    also: tuple[float, ...] = ()
    """Values accepted outside the bounds."""

    def contains(self, value: float) -> bool:
        """Whether ``value`` is finite and within the bounds (or one of ``also``)."""
        if value in self.also:
            return True
        if not math.isfinite(value):
            return False
        lower = (self.ge is None or value >= self.ge) and (self.gt is None or value > self.gt)
        return lower and (self.le is None or value <= self.le) and (self.lt is None or value < self.lt)

    def __str__(self) -> str:
        """Say the range in words: ``an integer >= 1``, ``a number in (0, 1]``."""
        kind = "an integer" if self.integer else "a number"
        lo = f"[{_num(self.ge)}" if self.ge is not None else f"({_num(self.gt)}" if self.gt is not None else ""
        hi = f"{_num(self.le)}]" if self.le is not None else f"{_num(self.lt)})" if self.lt is not None else ""
        if lo and hi:
            text = f"{kind} in {lo}, {hi}"
        else:
            ops = ((">=", self.ge), (">", self.gt), ("<=", self.le), ("<", self.lt))
            text = " ".join([kind, *(f"{op} {_num(v)}" for op, v in ops if v is not None)])
        return text + "".join(f" or {_num(v)}" for v in self.also)

    def fits(self, value: Any) -> bool:
        """Whether ``value`` is a number of the right kind within the range."""
        if isinstance(value, bool) or not isinstance(value, int | float):
            return False
        return self.contains(float(value)) and (not self.integer or float(value).is_integer())


def ranged(default: Any, *, integer: bool | None = None, **bounds: Any) -> Any:
    """A dataclass field with ``default`` and the :class:`Range` ``bounds`` (``ge``, ``gt``, ``le``, ``lt``, ``also``).

    ``integer`` defaults to whether ``default`` is an ``int`` (give it for interpolated defaults).
    """
    whole = isinstance(default, int) and not isinstance(default, bool) if integer is None else integer
    return field(default=default, metadata={RANGE_KEY: Range(integer=whole, **bounds)})


def each(*, integer: bool = False, **bounds: Any) -> dict[str, Range]:
    """Field ``metadata`` saying that every element of a list lies in the :class:`Range` ``bounds``."""
    return {RANGE_KEY: Range(integer=integer, **bounds)}


def range_of(f: dataclasses.Field[Any]) -> Range | None:
    """The :class:`Range` a field declares: its :data:`RANGE_KEY` entry or its plain bounds; None without one."""
    if RANGE_KEY in f.metadata:
        return f.metadata[RANGE_KEY]
    bounds = {k: f.metadata[k] for k in BOUND_KEYS if k in f.metadata}
    if not bounds:
        return None
    default = _default(f)
    whole = f.metadata.get("integer", isinstance(default, int) and not isinstance(default, bool))
    return Range(integer=bool(whole), **bounds)


def _schema_of(hint: Any) -> type | None:
    """The dataclass inside a field's type hint (``FooCfg`` or ``FooCfg | None``), else None."""
    for t in (hint, *typing.get_args(hint)) if isinstance(hint, types.UnionType) else (hint,):
        if dataclasses.is_dataclass(t) and isinstance(t, type):
            return t
    return None


def _default(f: dataclasses.Field[Any]) -> Any:
    """The field's default value (its factory's product for lists), or None."""
    if f.default is not dataclasses.MISSING:
        return f.default
    return f.default_factory() if f.default_factory is not dataclasses.MISSING else None


def _value_problem(key: str, value: Any, rng: Range, default: Any) -> str | None:
    """One-sentence message for ``value`` (a number, or a list of them) outside ``rng``, or None."""
    shown_default = "null" if default is None else repr(default)
    if isinstance(value, ListConfig | list | tuple):
        bad = [v for v in value if not rng.fits(v)]
        if not bad:
            return None
        what = f"{key}={list(value)} is out of range: its element {bad[0]!r} is not {rng}"
    elif rng.fits(value):
        return None
    else:
        what = f"{key}={value!r} is out of range: it must be {rng}"
    return f"{what} (default: {shown_default}). Set it within range, e.g. {key}={shown_default}."


def range_problem(cfg: DictConfig, schema: type, prefix: str = "") -> tuple[str, str] | None:
    """First value of ``cfg`` outside the range its ``schema`` field declares, as ``(key, message)``; else None.

    Sections that are None or not dicts, and values still ``???``, are skipped (other checks report those).
    """
    hints = typing.get_type_hints(schema)
    for f in dataclasses.fields(schema):
        if f.name not in cfg or OmegaConf.is_missing(cfg, f.name):
            continue
        key, value = f"{prefix}{f.name}", cfg[f.name]
        sub = _schema_of(hints[f.name])
        if sub is not None and isinstance(value, DictConfig):
            found = range_problem(value, sub, f"{key}.")
            if found:
                return found
            continue
        rng = range_of(f)
        if rng is None or value is None:
            continue
        message = _value_problem(key, value, rng, _default(f))
        if message:
            return key, message
    return None
