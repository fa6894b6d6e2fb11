# SPDX-License-Identifier: Apache-2.0
"""Command-line flags generated from the fields of a typed config dataclass.

A :class:`Flag` names one field by its dotted path (``solver.voxel_size``); the rest comes from the config: the
type, ``nargs`` and choices from the field's annotation (``X | None``, ``tuple[X, ...]``, ``Literal`` and ``Enum``
fields), the default from the config's defaults, the help from the field's docstring (the string literal on the
line after the field, inherited fields included) and the valid range from its ``metadata`` (``ge`` / ``gt`` /
``le`` / ``lt``, and ``also`` for values accepted outside them). A boolean field is a switch that turns it off
(``--no-mcap``, ``off=True``) or on (``--resume``); a tuple field takes its values as separate words
(``--speeds 0.5 1.0``) or, with ``sep``, as one word (``--speeds 0.5,1.0``). The flag names belong to the command
line, so recorded commands keep running when a field is renamed.

Standard library only, so every package that depends on ``gmloco-deploy`` may use it without pulling in Warp,
MuJoCo or torch.
"""

from __future__ import annotations

import argparse
import ast
import dataclasses
import inspect
import itertools
import textwrap
import types
import typing
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from enum import Enum
from functools import cache
from typing import Any

__all__ = [
    "Flag",
    "add_flags",
    "cfg_from_flags",
    "check_flags",
    "field_doc",
    "flag_args",
    "flag_problem",
    "get_value",
    "unflagged",
    "with_values",
]


@dataclass(frozen=True)
class Flag:
    """One command-line flag that sets one field of a config dataclass."""

    name: str
    """The flag as typed, e.g. ``--voxel``; its ``argparse`` destination is the name without dashes."""
    path: str
    """Dotted path of the field in the config, e.g. ``solver.voxel_size``."""
    off: bool = False
    """A switch that sets the boolean field to False (``--no-refill``); else a flag taking the field's value, or
    for a boolean field a switch that sets it to True (``--resume``)."""
    sep: str | None = None
    """For a tuple field: the values come as one word split at this separator (``","``: ``0.5,1.0``); None: as
    separate words (``nargs="+"``)."""
    parse: Callable[[str], Any] | None = None
    """Parser of the flag's word into the field's value, for a format the annotation does not tell (it raises
    ``argparse.ArgumentTypeError`` on bad input); None: parsed from the annotation."""

    @property
    def dest(self) -> str:
        """The ``argparse`` attribute of the flag (``--frame-dt`` -> ``frame_dt``)."""
        return self.name.lstrip("-").replace("-", "_")


def _field(cls: type, path: str) -> tuple[type, dataclasses.Field[Any], Any]:
    """The dataclass that holds ``path``'s last part, its field and the field's resolved type."""
    owner: type = cls
    *parents, name = path.split(".")
    for part in parents:
        owner = typing.get_type_hints(owner)[part]
    found = {f.name: f for f in dataclasses.fields(owner)}  # type: ignore[arg-type]
    return owner, found[name], typing.get_type_hints(owner)[name]


@cache
def _docs(owner: type) -> dict[str, str]:
    """The docstrings under the fields a dataclass itself declares, read from its source."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(owner)))
    body = tree.body[0].body  # type: ignore[attr-defined]
    out: dict[str, str] = {}
    for node, after in itertools.pairwise(body):
        target = node.target if isinstance(node, ast.AnnAssign) else None
        if isinstance(target, ast.Name) and isinstance(after, ast.Expr) and isinstance(after.value, ast.Constant):
            out[target.id] = inspect.cleandoc(str(after.value.value))
    return out


def field_doc(cls: type, path: str) -> str:
    """The docstring of the field at ``path`` of ``cls``, from the class that declares it (empty when it has none)."""
    owner, f, _ = _field(cls, path)
    for klass in owner.__mro__:
        if dataclasses.is_dataclass(klass) and f.name in getattr(klass, "__annotations__", {}):
            return _docs(klass).get(f.name, "")
    return ""


def _value_type(hint: Any) -> tuple[Any, int | None]:
    """The type of one value of a field (``X | None`` -> X, ``tuple[X, ...]`` -> X) and how many it holds.

    The count is None for a single value, 0 for ``tuple[X, ...]`` and n for a fixed-length tuple of n.
    """
    if isinstance(hint, types.UnionType) or typing.get_origin(hint) is typing.Union:
        hint = next(t for t in typing.get_args(hint) if t is not type(None))
    if typing.get_origin(hint) is tuple:
        args = typing.get_args(hint)
        return args[0], 0 if len(args) == 2 and args[1] is Ellipsis else len(args)
    return hint, None


def _choices(kind: Any) -> list[Any] | None:
    """The values a ``Literal`` or ``Enum`` type allows (an enum by its members' values); None for other types."""
    if typing.get_origin(kind) is typing.Literal:
        return list(typing.get_args(kind))
    if isinstance(kind, type) and issubclass(kind, Enum):
        return [m.value for m in kind]
    return None


def get_value(cfg: Any, path: str) -> Any:
    """The value at a dotted ``path`` of a (nested) dataclass."""
    for part in path.split("."):
        cfg = getattr(cfg, part)
    return cfg


def with_values(cfg: Any, values: dict[str, Any]) -> Any:
    """``cfg`` with the values at dotted paths replaced (nested dataclasses replaced in turn)."""
    own = {p: v for p, v in values.items() if "." not in p}
    nested: dict[str, dict[str, Any]] = {}
    for path, value in values.items():
        if "." in path:
            head, rest = path.split(".", 1)
            nested.setdefault(head, {})[rest] = value
    own |= {head: with_values(getattr(cfg, head), sub) for head, sub in nested.items()}
    return replace(cfg, **own)


def _text(value: Any) -> str:
    """One value as the command line writes it (floats exactly, enums by value)."""
    if isinstance(value, Enum):
        return str(value.value)
    return repr(value) if isinstance(value, float) else str(value)


def _switch(cls: type, flag: Flag) -> bool | None:
    """The value a switch sets: False for ``off``, True for a boolean field's plain flag, None for a valued flag."""
    if flag.off:
        return False
    return True if _field(cls, flag.path)[2] is bool else None


def _help(cls: type, flag: Flag, default: Any) -> str:
    """The flag's help: the field's docstring (its first paragraph, ``%`` escaped for argparse) and the default."""
    doc = field_doc(cls, flag.path).split("\n\n")[0].replace("\n", " ").replace("%", "%%")
    if (sets := _switch(cls, flag)) is not None:
        return f"{flag.path} = {sets}. {doc}"
    if flag.sep is not None:
        shown = flag.sep.join(_text(v) for v in default) if isinstance(default, tuple) else str(default)
        return f"{doc} Values separated by '{flag.sep}'. Default: {shown.replace('%', '%%')}."
    return f"{doc} Default: %(default)s."


def _word_parser(kind: Any) -> Callable[[str], Any]:
    """Parser of one word into one value of type ``kind``, naming the expected type when the word is not one."""
    choices = _choices(kind)

    def parse(word: str) -> Any:
        """One value of the flag."""
        if choices is not None:
            value = next((c for c in choices if str(c) == word), None)
            if value is None:
                raise argparse.ArgumentTypeError(f"{word!r}: choose from {', '.join(map(str, choices))}")
            return kind(value) if isinstance(kind, type) and issubclass(kind, Enum) else value
        try:
            return kind(word)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{word!r}: expected a {getattr(kind, '__name__', kind)}") from None

    return parse


def _split_parser(flag: Flag, kind: Any, count: int) -> Callable[[str], tuple[Any, ...]]:
    """Parser of one ``sep``-separated word into a tuple (``count`` values, or any number >= 1 for 0)."""
    one, sep = _word_parser(kind), flag.sep or ","
    example = sep.join(["1", "2"] if count in (0, 2) else ["1"] * count)

    def parse(text: str) -> tuple[Any, ...]:
        """The values of the flag."""
        words = [w.strip() for w in text.split(sep) if w.strip()]
        if not words or (count and len(words) != count):
            many = f"{count}" if count else "one or more"
            raise argparse.ArgumentTypeError(f"{text!r}: expected {many} values separated by {sep!r}, e.g. {example}")
        return tuple(one(w) for w in words)

    return parse


def _type_or_choices(kind: Any) -> dict[str, Any]:
    """``argparse`` keywords of one value: ``choices`` for an enum (by value) or ``Literal``, else ``type``."""
    choices = _choices(kind)
    if choices is None:
        return {"type": kind}
    is_enum = isinstance(kind, type) and issubclass(kind, Enum)
    return {"choices": choices} if is_enum else {"choices": choices, "type": type(choices[0])}


def add_flags(parser: argparse.ArgumentParser, base: Any, flags: Sequence[Flag]) -> None:
    """Add ``flags`` to ``parser``: types, choices and help from the fields of ``base``'s class, defaults from ``base``."""
    cls = type(base)
    for flag in flags:
        value = get_value(base, flag.path)
        if _switch(cls, flag) is not None:
            parser.add_argument(flag.name, action="store_true", help=_help(cls, flag, value))
            continue
        kind, count = _value_type(_field(cls, flag.path)[2])
        kwargs: dict[str, Any] = {"help": _help(cls, flag, value)}
        if flag.parse is not None:
            kwargs |= {"type": flag.parse, "default": value}
        elif count is not None and flag.sep is not None:
            kwargs |= {"type": _split_parser(flag, kind, count), "default": value}
        else:
            many = count is not None
            kwargs |= {
                "default": list(value) if many else value,
                "nargs": ("+" if count == 0 else count) if many else None,
            }
            kwargs |= _type_or_choices(kind)
        parser.add_argument(flag.name, **kwargs)


def _bounds_text(metadata: Any) -> str | None:
    """The metadata's bounds in words (``>= 1``, ``> 0 and <= 0.02``, ``>= 1 or 0``); None without bounds."""
    ops = (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<"))
    parts = [f"{op} {metadata[k]:g}" for k, op in ops if k in metadata]
    if not parts:
        return None
    return " and ".join(parts) + "".join(f" or {v:g}" for v in metadata.get("also", ()))


def _fits(value: float, metadata: Any) -> bool:
    """Whether ``value`` lies within the metadata's bounds (or is one of its ``also`` values)."""
    if value in metadata.get("also", ()):
        return True
    checks = {"ge": value >= metadata.get("ge", value), "gt": "gt" not in metadata or value > metadata["gt"]}
    checks |= {"le": value <= metadata.get("le", value), "lt": "lt" not in metadata or value < metadata["lt"]}
    return all(checks.values())


def flag_problem(cls: type, flag: Flag, value: Any) -> str | None:
    """``FLAG VALUE must be ...`` for a parsed value outside its field's range in ``cls``, else None."""
    metadata = _field(cls, flag.path)[1].metadata
    words = _bounds_text(metadata)
    if words is None or value is None or _switch(cls, flag) is not None:
        return None
    for v in value if isinstance(value, list | tuple) else [value]:
        if not _fits(v, metadata):
            return f"{flag.name} {v} must be {words}"
    return None


def check_flags(parser: argparse.ArgumentParser, args: argparse.Namespace, cls: type, flags: Sequence[Flag]) -> None:
    """Stop with a usage error (exit code 2) naming the first parsed value outside its field's range."""
    for flag in flags:
        if (problem := flag_problem(cls, flag, getattr(args, flag.dest))) is not None:
            parser.error(problem)


def cfg_from_flags(args: argparse.Namespace, base: Any, flags: Sequence[Flag]) -> Any:
    """``base`` with the fields of ``flags`` set from parsed arguments (lists become the fields' tuples)."""
    values: dict[str, Any] = {}
    for flag in flags:
        given = getattr(args, flag.dest)
        if (sets := _switch(type(base), flag)) is not None:
            values[flag.path] = sets if given else get_value(base, flag.path)
            continue
        kind = _value_type(_field(type(base), flag.path)[2])[0]
        cast = kind if isinstance(kind, type) and issubclass(kind, Enum) else (lambda v: v)
        if isinstance(given, list):
            values[flag.path] = tuple(cast(v) for v in given)
        else:
            values[flag.path] = given if given is None or isinstance(given, tuple) else cast(given)
    return with_values(base, values)


def flag_args(cfg: Any, flags: Sequence[Flag]) -> list[str]:
    """The arguments of ``flags`` that give back ``cfg``'s values (a switch only when its field has its value)."""
    out: list[str] = []
    for flag in flags:
        value = get_value(cfg, flag.path)
        if (sets := _switch(type(cfg), flag)) is not None:
            out += [flag.name] if value == sets else []
        elif value is None:
            continue
        elif isinstance(value, tuple | list) and flag.sep is not None:
            out += [flag.name, flag.sep.join(_text(v) for v in value)]
        elif isinstance(value, tuple | list):
            out += [flag.name, *(_text(v) for v in value)]
        else:
            out += [flag.name, _text(value)]
    return out


def unflagged(a: Any, b: Any, prefix: str = "") -> list[str]:
    """Dotted paths of the fields in which two configs of one dataclass type differ."""
    out: list[str] = []
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if dataclasses.is_dataclass(x) and type(x) is type(y):
            out += unflagged(x, y, f"{prefix}{f.name}.")
        elif x != y:
            out.append(f"{prefix}{f.name}")
    return out
