# SPDX-License-Identifier: Apache-2.0
"""Command-line flags of :class:`~gmloco.eval.g1.config.G1EvalCfg`, generated from its fields.

A :class:`Flag` names one field by its dotted path (``solver.voxel_size``); the rest comes from the config: the type,
``nargs`` and choices from the field's annotation, the default from ``G1EvalCfg()``, the help from the field's
docstring and the valid range from its ``metadata`` (``ge`` / ``gt`` / ``le`` / ``lt`` / ``also``, the bounds the
pipeline's ``eval_mpm`` section is checked against). A boolean field is a switch that turns it off
(``--no-mcap``, ``--static-bed``). The flag names are the command line's own, shorter than the field paths, so that
the commands recorded in ``results/**/manifest.json`` still run.
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
from dataclasses import dataclass, replace
from enum import Enum
from functools import cache
from typing import Any

from gmloco.eval.g1.config import G1EvalCfg

__all__ = [
    "FLAGS",
    "Flag",
    "add_flags",
    "cfg_from_flags",
    "field_doc",
    "flag_args",
    "flag_problem",
    "get_value",
    "unflagged",
    "with_values",
]


@dataclass(frozen=True)
class Flag:
    """One command-line flag that sets one field of ``G1EvalCfg``."""

    name: str
    """The flag as typed, e.g. ``--voxel``; its ``argparse`` destination is the name without dashes."""
    path: str
    """Dotted path of the field in ``G1EvalCfg``, e.g. ``solver.voxel_size``."""
    off: bool = False
    """A switch that sets the boolean field to False (``--no-refill``); else a flag taking the field's value."""

    @property
    def dest(self) -> str:
        """The ``argparse`` attribute of the flag (``--frame-dt`` -> ``frame_dt``)."""
        return self.name.lstrip("-").replace("-", "_")


FLAGS: tuple[Flag, ...] = (
    Flag("--policy", "policy_path"),
    Flag("--terrains", "terrains"),
    Flag("--scenarios", "scenarios"),
    Flag("--speeds", "speeds"),
    Flag("--num-episodes", "num_episodes"),
    Flag("--episode-s", "episode_s"),
    Flag("--circle-radius", "circle_radius"),
    Flag("--course-slack", "course_slack"),
    Flag("--voxel", "solver.voxel_size"),
    Flag("--iters", "solver.max_iterations"),
    Flag("--frame-dt", "solver.frame_dt"),
    Flag("--tolerance", "solver.tolerance"),
    Flag("--rheology-solver", "solver.rheology_solver"),
    Flag("--substeps", "solver.rigid_substeps"),
    Flag("--bed-depth", "bed_depth"),
    Flag("--robots-per-batch", "robots_per_batch"),
    Flag("--no-refill", "refill", off=True),
    Flag("--keep-idle-lanes", "retire_idle_lanes", off=True),
    Flag("--static-bed", "window.moving", off=True),
    Flag("--window-length", "window.length"),
    Flag("--window-width", "window.width"),
    Flag("--window-lead", "window.lead"),
    Flag("--window-fixed-axes", "window.turn_with_robot", off=True),
    Flag("--window-turn-step", "window.turn_step"),
    Flag("--particles-per-voxel", "window.particles_per_voxel"),
    Flag("--cell-capacity-factor", "cell_capacity_factor"),
    Flag("--no-mcap", "record_mcap", off=True),
    Flag("--max-minutes", "max_minutes"),
    Flag("--no-fit-time-box", "fit_time_box", off=True),
    Flag("--fresh", "resume", off=True),
    Flag("--device", "device"),
    Flag("--seed", "seed"),
)
"""Every ``G1EvalCfg`` field the command line sets, in ``--help`` order (``--out`` and ``--shard`` are the
command line's own: a required folder, and ``shard`` / ``shards`` written as one ``I/N``)."""


def _field(path: str) -> tuple[type, dataclasses.Field[Any], Any]:
    """The dataclass that declares ``path``'s last part, its field and the field's resolved type."""
    owner: type = G1EvalCfg
    *parents, name = path.split(".")
    for part in parents:
        owner = typing.get_type_hints(owner)[part]
    found = {f.name: f for f in dataclasses.fields(owner)}  # type: ignore[arg-type]
    return owner, found[name], typing.get_type_hints(owner)[name]


@cache
def _docs(owner: type) -> dict[str, str]:
    """The docstrings under the fields of a dataclass, read from its source."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(owner)))
    body = tree.body[0].body  # type: ignore[attr-defined]
    out: dict[str, str] = {}
    for node, after in itertools.pairwise(body):
        target = node.target if isinstance(node, ast.AnnAssign) else None
        if isinstance(target, ast.Name) and isinstance(after, ast.Expr) and isinstance(after.value, ast.Constant):
            out[target.id] = inspect.cleandoc(str(after.value.value))
    return out


def field_doc(path: str) -> str:
    """The docstring of the field at ``path`` (empty when it has none)."""
    owner, f, _ = _field(path)
    return _docs(owner).get(f.name, "")


def _value_type(hint: Any) -> tuple[Any, bool]:
    """The type of one value of a field (``X | None`` -> X, ``tuple[X, ...]`` -> X) and whether it is a tuple."""
    if isinstance(hint, types.UnionType):
        hint = next(t for t in typing.get_args(hint) if t is not type(None))
    if typing.get_origin(hint) is tuple:
        return typing.get_args(hint)[0], True
    return hint, False


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


def _help(flag: Flag) -> str:
    """The flag's help: the field's docstring (its first paragraph, ``%`` escaped for argparse) and the default."""
    doc = field_doc(flag.path).split("\n\n")[0].replace("\n", " ").replace("%", "%%")
    return f"{flag.path} = False. {doc}" if flag.off else f"{doc} Default: %(default)s."


def add_flags(parser: argparse.ArgumentParser, flags: tuple[Flag, ...] = FLAGS) -> None:
    """Add ``flags`` to ``parser``, with the types, defaults, choices and help of their fields."""
    default = G1EvalCfg()
    for flag in flags:
        if flag.off:
            parser.add_argument(flag.name, action="store_true", help=_help(flag))
            continue
        kind, many = _value_type(_field(flag.path)[2])
        value = get_value(default, flag.path)
        kwargs: dict[str, Any] = {"default": list(value) if many else value, "help": _help(flag)}
        if isinstance(kind, type) and issubclass(kind, Enum):
            kwargs["choices"] = [m.value for m in kind]
        else:
            kwargs["type"] = kind
        parser.add_argument(flag.name, nargs="+" if many else None, **kwargs)


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


def flag_problem(flag: Flag, value: Any) -> str | None:
    """``FLAG VALUE must be ...`` for a parsed value outside its field's range, else None."""
    metadata = _field(flag.path)[1].metadata
    words = _bounds_text(metadata)
    if words is None or value is None or flag.off:
        return None
    for v in value if isinstance(value, list) else [value]:
        if not _fits(v, metadata):
            return f"{flag.name} {v} must be {words}"
    return None


def cfg_from_flags(a: argparse.Namespace, base: G1EvalCfg, flags: tuple[Flag, ...] = FLAGS) -> G1EvalCfg:
    """``base`` with the fields of ``flags`` set from parsed arguments (lists become the fields' tuples)."""
    values: dict[str, Any] = {}
    for flag in flags:
        given = getattr(a, flag.dest)
        if flag.off:
            values[flag.path] = not given
            continue
        kind, many = _value_type(_field(flag.path)[2])
        cast = kind if isinstance(kind, type) and issubclass(kind, Enum) else (lambda v: v)
        values[flag.path] = tuple(cast(v) for v in given) if many else given
    return with_values(base, values)


def _text(value: Any) -> str:
    """One value as the command line writes it (floats exactly, enums by name)."""
    if isinstance(value, Enum):
        return str(value.value)
    return repr(value) if isinstance(value, float) else str(value)


def flag_args(cfg: G1EvalCfg, flags: tuple[Flag, ...] = FLAGS) -> list[str]:
    """The arguments of ``flags`` that give back ``cfg``'s values (a switch only when its field is False)."""
    out: list[str] = []
    for flag in flags:
        value = get_value(cfg, flag.path)
        if flag.off:
            out += [flag.name] if not value else []
        elif value is not None:
            many = isinstance(value, tuple | list)
            out += [flag.name, *(_text(v) for v in value)] if many else [flag.name, _text(value)]
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
