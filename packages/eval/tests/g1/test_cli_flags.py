# SPDX-License-Identifier: Apache-2.0
"""The MPM evaluation's flags come from ``G1EvalCfg``: names kept, defaults, help and ranges from the fields."""

from __future__ import annotations

import argparse
from dataclasses import replace

import pytest

from gmloco.eval.g1.cli import _parse, cfg_from_args
from gmloco.eval.g1.cli_flags import FLAGS, Flag, add_flags, field_doc, flag_problem
from gmloco.eval.g1.config import G1EvalCfg

RECORDED_FLAGS = [
    "--policy",
    "--terrains",
    "--scenarios",
    "--speeds",
    "--num-episodes",
    "--episode-s",
    "--circle-radius",
    "--course-slack",
    "--voxel",
    "--iters",
    "--frame-dt",
    "--tolerance",
    "--rheology-solver",
    "--substeps",
    "--bed-depth",
    "--robots-per-batch",
    "--no-refill",
    "--keep-idle-lanes",
    "--static-bed",
    "--window-length",
    "--window-width",
    "--window-lead",
    "--window-fixed-axes",
    "--window-turn-step",
    "--particles-per-voxel",
    "--cell-capacity-factor",
    "--no-mcap",
    "--max-minutes",
    "--no-fit-time-box",
    "--fresh",
    "--device",
    "--seed",
]
"""The flags the recorded commands (``results/**/manifest.json``) use, besides ``--out`` and ``--shard``."""


def test_the_recorded_flag_names_are_kept() -> None:
    """Every flag of the commands already written down still exists, in its order, each naming one field."""
    assert [f.name for f in FLAGS if f.name in RECORDED_FLAGS] == RECORDED_FLAGS
    assert len({f.path for f in FLAGS}) == len(FLAGS)


def test_no_flags_give_the_evaluation_defaults() -> None:
    """Without flags the command line scores at ``G1EvalCfg()`` (only the folder is its own)."""
    assert cfg_from_args(_parse(["--out", "x"])) == replace(G1EvalCfg(), out_dir="x")


def test_help_is_the_field_docstring() -> None:
    """A flag's help quotes its field's docstring; a switch says which field it turns off."""
    parser = argparse.ArgumentParser()
    add_flags(parser)
    text = parser.format_help().replace("\n", " ")
    assert "Rigid-solver substeps per frame." in " ".join(text.split())
    assert field_doc("solver.voxel_size").startswith("Grid voxel size [m]")
    assert "record_mcap = False." in text


@pytest.mark.parametrize(
    ("flag", "value", "words"),
    [
        (Flag("--course-slack", "course_slack"), 1.0, "--course-slack 1.0 must be >= 0 and < 1"),
        (Flag("--frame-dt", "solver.frame_dt"), 0.04, "--frame-dt 0.04 must be > 0 and <= 0.02"),
        (Flag("--cell-capacity-factor", "cell_capacity_factor"), 0.5, "must be >= 1 or 0"),
        (Flag("--speeds", "speeds"), [1.0, -2.0], "--speeds -2.0 must be > 0"),
    ],
)
def test_ranges_come_from_the_field_metadata(flag: Flag, value: object, words: str) -> None:
    """A value outside the bounds in the field's ``metadata`` is named with the bounds in words."""
    problem = flag_problem(flag, value)
    assert problem is not None and words in problem


def test_values_within_range_pass() -> None:
    """0 is an accepted capacity factor (unbounded) and a 5 ms frame fits."""
    assert flag_problem(Flag("--cell-capacity-factor", "cell_capacity_factor"), 0.0) is None
    assert flag_problem(Flag("--frame-dt", "solver.frame_dt"), 0.005) is None
