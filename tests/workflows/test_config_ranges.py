# SPDX-License-Identifier: Apache-2.0
"""Declared ranges of the config fields: the words they print, what they accept, and that every default fits."""

from __future__ import annotations

import dataclasses
import math
import typing
from dataclasses import dataclass, field

import pytest
from omegaconf import OmegaConf

from workflows import schemas
from workflows.config_ranges import Range, each, range_of, range_problem, ranged


@pytest.mark.parametrize(
    ("rng", "text"),
    [
        (Range(ge=1, integer=True), "an integer >= 1"),
        (Range(gt=0), "a number > 0"),
        (Range(gt=0, le=0.02), "a number in (0, 0.02]"),
        (Range(ge=0, le=2**32 - 1, integer=True), "an integer in [0, 4294967295]"),
        (Range(ge=1, also=(0.0,)), "a number >= 1 or 0"),
    ],
)
def test_range_says_itself_in_words(rng: Range, text: str) -> None:
    """Each range prints as the sentence the error message quotes."""
    assert str(rng) == text


def test_range_accepts_only_finite_numbers_of_the_right_kind() -> None:
    """Bounds are inclusive or exclusive as declared; NaN, inf, bools and fractions of integers are refused."""
    unit = Range(gt=0, le=1)
    assert unit.fits(1) and unit.fits(0.5) and not unit.fits(0) and not unit.fits(1.0 + 1e-12)
    assert not unit.fits(math.nan) and not Range(ge=0).fits(math.inf) and not Range(ge=0).fits(True)
    assert Range(ge=1, integer=True).fits(3) and not Range(ge=1, integer=True).fits(2.5)
    assert Range(ge=1, also=(0.0,)).fits(0) and not Range(ge=1, also=(0.0,)).fits(0.5)


@dataclass
class _InnerCfg:
    """A nested section."""

    rate: float = ranged(0.5, gt=0, lt=1)
    """A fraction."""
    widths: list[int] = field(default_factory=lambda: [8, 8], metadata=each(integer=True, ge=1))
    """Layer widths."""


@dataclass
class _OuterCfg:
    """A toy top level."""

    count: int = ranged(3, ge=1)
    """How many."""
    limit: float | None = ranged(None, gt=0)
    """Optional limit."""
    inner: _InnerCfg = field(default_factory=_InnerCfg)
    """Required section."""
    extra: _InnerCfg | None = None
    """Optional section."""


@pytest.mark.parametrize(
    ("values", "key", "words"),
    [
        ({}, None, ""),
        ({"count": 0}, "count", "count=0 is out of range: it must be an integer >= 1 (default: 3)."),
        ({"limit": -1.0}, "limit", "limit=-1.0 is out of range: it must be a number > 0 (default: null)."),
        ({"inner": {"rate": 1.0}}, "inner.rate", "inner.rate=1.0 is out of range: it must be a number in (0, 1)"),
        ({"inner": {"widths": [8, 0]}}, "inner.widths", "its element 0 is not an integer >= 1 (default: [8, 8])"),
        ({"extra": {"rate": 2.0}}, "extra.rate", "extra.rate=2.0"),
    ],
)
def test_range_problem_names_the_dotted_key(values: dict, key: str | None, words: str) -> None:
    """The first value outside its range comes back with its dotted key; optional sections left None are skipped."""
    cfg = OmegaConf.merge(OmegaConf.structured(_OuterCfg), values)
    found = range_problem(cfg, _OuterCfg)  # type: ignore[arg-type]
    if key is None:
        assert found is None
    else:
        assert found is not None and found[0] == key and words in found[1]


def _schema_classes(cls: type, seen: set[type]) -> None:
    """Add ``cls`` and every dataclass its fields hold (``FooCfg`` or ``FooCfg | None``) to ``seen``."""
    if cls in seen:
        return
    seen.add(cls)
    for hint in typing.get_type_hints(cls).values():
        for t in (hint, *typing.get_args(hint)):
            if isinstance(t, type) and dataclasses.is_dataclass(t):
                _schema_classes(t, seen)


def _ranged_fields() -> list[tuple[str, dataclasses.Field]]:
    """Every field that declares a range: the pipeline's schemas and the package dataclasses they hold."""
    classes: set[type] = set()
    for cls in vars(schemas).values():
        if isinstance(cls, type) and dataclasses.is_dataclass(cls) and cls.__module__ == schemas.__name__:
            _schema_classes(cls, classes)
    fields = [(f"{cls.__name__}.{f.name}", f) for cls in classes for f in dataclasses.fields(cls)]
    return [(name, f) for name, f in fields if range_of(f) is not None]


def test_every_schema_default_lies_in_its_range() -> None:
    """The defaults the schemas declare pass their own ranges (interpolations are checked once composed)."""
    fields = _ranged_fields()
    assert len(fields) > 50  # the numeric settings of every stage, the sweep and the ablation
    for name, f in fields:
        default = f.default_factory() if f.default_factory is not dataclasses.MISSING else f.default
        if default is None or isinstance(default, str):
            continue
        rng = range_of(f)
        assert rng is not None
        assert all(rng.fits(v) for v in (default if isinstance(default, list | tuple) else [default])), name
