# SPDX-License-Identifier: Apache-2.0
"""Flags generated from a config dataclass: types, defaults, help and ranges from the fields; bad input exits 2."""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from enum import Enum
from typing import Literal

import pytest

from gmloco.deploy.config_cli import (
    Flag,
    add_flags,
    cfg_from_flags,
    check_flags,
    field_doc,
    flag_args,
    flag_problem,
    unflagged,
)


class Gait(Enum):
    """A closed choice given by value on the command line."""

    walk = "walk"
    trot = "trot"


@dataclass
class ToySolverCfg:
    """A nested group."""

    voxel_size: float = field(default=0.05, metadata={"gt": 0, "le": 0.2})
    """Grid voxel size [m]."""
    iterations: int = field(default=10, metadata={"ge": 1, "also": (0,)})
    """Sweeps per frame; 0 runs to the tolerance."""


@dataclass
class ToyBaseCfg:
    """A parent whose field docstrings the child inherits."""

    duration_s: float = field(default=10.0, metadata={"gt": 0})
    """Episode length [s]."""


@dataclass
class ToyCfg(ToyBaseCfg):
    """A config with every kind of field the flags handle."""

    speeds: tuple[float, ...] = field(default=(0.5, 1.0), metadata={"gt": 0})
    """Forward speeds [m/s]."""
    grid: tuple[int, int] = field(default=(3, 3), metadata={"ge": 1})
    """Points along each axis."""
    gait: Gait = Gait.walk
    """Foot pattern."""
    model: Literal["rft3d", "rigid"] = "rft3d"
    """Contact model."""
    record: bool = True
    """Write a recording."""
    resume: bool = False
    """Skip the finished episodes."""
    names: tuple[str, ...] = ("a",)
    """Names, as separate words."""
    label: str | None = None
    """Optional label."""
    solver: ToySolverCfg = field(default_factory=ToySolverCfg)
    """The solver."""


FLAGS = (
    Flag("--seconds", "duration_s"),
    Flag("--speeds", "speeds", sep=","),
    Flag("--grid", "grid", sep=","),
    Flag("--gait", "gait"),
    Flag("--model", "model"),
    Flag("--no-record", "record", off=True),
    Flag("--resume", "resume"),
    Flag("--names", "names"),
    Flag("--label", "label"),
    Flag("--voxel", "solver.voxel_size"),
    Flag("--iters", "solver.iterations"),
)
"""One flag per kind of field."""


def _parser() -> argparse.ArgumentParser:
    """A parser of ``FLAGS`` over ``ToyCfg()``."""
    parser = argparse.ArgumentParser(prog="toy")
    add_flags(parser, ToyCfg(), FLAGS)
    return parser


def _cfg(argv: list[str]) -> ToyCfg:
    """The config of ``argv``, range-checked as a command line does."""
    parser = _parser()
    args = parser.parse_args(argv)
    check_flags(parser, args, ToyCfg, FLAGS)
    return cfg_from_flags(args, ToyCfg(), FLAGS)


def test_no_flags_give_the_defaults() -> None:
    """Without flags the config is ``ToyCfg()``."""
    assert _cfg([]) == ToyCfg()


def test_flags_set_nested_tuple_enum_literal_and_switch_fields() -> None:
    """Each flag sets its field, with the field's type."""
    argv = ["--seconds", "4", "--speeds", "1.5, 2", "--grid", "2,1", "--gait", "trot", "--model", "rigid",
            "--no-record", "--resume", "--names", "x", "y", "--label", "l", "--voxel", "0.1", "--iters", "0"]  # fmt: skip
    cfg = _cfg(argv)
    assert cfg == ToyCfg(duration_s=4.0, speeds=(1.5, 2.0), grid=(2, 1), gait=Gait.trot, model="rigid", record=False,
                         resume=True, names=("x", "y"), label="l", solver=ToySolverCfg(voxel_size=0.1, iterations=0))  # fmt: skip
    assert unflagged(cfg, ToyCfg()) == [
        "duration_s", "speeds", "grid", "gait", "model", "record", "resume", "names", "label", "solver.voxel_size",
        "solver.iterations",
    ]  # fmt: skip


def test_flag_args_give_the_config_back() -> None:
    """The arguments written for a config parse back to it (separated tuples as one word)."""
    cfg = ToyCfg(speeds=(0.25,), record=False, resume=True, names=("p", "q"), solver=ToySolverCfg(iterations=3))
    args = flag_args(cfg, FLAGS)
    assert args[args.index("--speeds") + 1] == "0.25" and "--no-record" in args and "--resume" in args
    assert "--resume" not in flag_args(ToyCfg(), FLAGS)
    assert _cfg(args) == cfg


def test_help_is_the_field_docstring_with_the_default() -> None:
    """Help quotes the docstring (inherited ones too) and the default, written as the command line takes it."""
    text = " ".join(_parser().format_help().split())
    assert "Episode length [s]. Default: 10.0." in text
    assert "Forward speeds [m/s]. Values separated by ','. Default: 0.5,1.0." in text
    assert "record = False. Write a recording." in text
    assert "resume = True. Skip the finished episodes." in text
    assert field_doc(ToyCfg, "solver.voxel_size") == "Grid voxel size [m]."


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--seconds", "0"], "--seconds 0.0 must be > 0"),
        (["--speeds", "1,-2"], "--speeds -2.0 must be > 0"),
        (["--grid", "0,2"], "--grid 0 must be >= 1"),
        (["--voxel", "0.5"], "--voxel 0.5 must be > 0 and <= 0.2"),
        (["--iters", "-1"], "--iters -1 must be >= 1 or 0"),
        (["--seconds", "soon"], "argument --seconds: invalid float value: 'soon'"),
        (["--speeds", "1,fast"], "argument --speeds: 'fast': expected a float"),
        (["--speeds", ","], "argument --speeds: ',': expected one or more values separated by ','"),
        (["--grid", "1,2,3"], "argument --grid: '1,2,3': expected 2 values separated by ','"),
        (["--gait", "gallop"], "argument --gait: invalid choice: 'gallop'"),
        (["--model", "mpm"], "argument --model: invalid choice: 'mpm'"),
    ],
)
def test_bad_values_exit_2_naming_the_flag(argv: list[str], words: str, capsys: pytest.CaptureFixture[str]) -> None:
    """An out-of-range or malformed value is a usage error (exit code 2) naming the flag and what it must be."""
    with pytest.raises(SystemExit) as stop:
        _cfg(argv)
    assert stop.value.code == 2
    assert words in capsys.readouterr().err


def test_values_within_range_pass() -> None:
    """The bound itself (``le``) and an ``also`` value are accepted."""
    assert flag_problem(ToyCfg, Flag("--voxel", "solver.voxel_size"), 0.2) is None
    assert flag_problem(ToyCfg, Flag("--iters", "solver.iterations"), 0) is None


def test_a_custom_parser_replaces_the_annotation() -> None:
    """``parse`` reads a format of its own; default and help still come from the field."""

    def upper(text: str) -> tuple[str, ...]:
        """Names in capitals."""
        return tuple(text.upper().split("+"))

    parser = argparse.ArgumentParser()
    flags = (Flag("--names", "names", parse=upper),)
    add_flags(parser, ToyCfg(), flags)
    assert cfg_from_flags(parser.parse_args(["--names", "a+b"]), ToyCfg(), flags).names == ("A", "B")
    assert cfg_from_flags(parser.parse_args([]), ToyCfg(), flags).names == ("a",)
