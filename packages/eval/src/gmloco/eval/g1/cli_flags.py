# SPDX-License-Identifier: Apache-2.0
"""Command-line flags of :class:`~gmloco.eval.g1.config.G1EvalCfg`: the flag table over its fields.

A :class:`~gmloco.deploy.config_cli.Flag` names one field by its dotted path (``solver.voxel_size``); the rest
comes from the config (:mod:`gmloco.deploy.config_cli`): the type, ``nargs`` and choices from the field's
annotation, the default from ``G1EvalCfg()``, the help from the field's docstring and the valid range from its
``metadata`` (``ge`` / ``gt`` / ``le`` / ``lt`` / ``also``, the bounds the pipeline's ``eval_mpm`` section is
checked against). A boolean field is a switch that turns it off (``--no-mcap``, ``--static-bed``). The flag names
are the command line's own, shorter than the field paths, so that the commands recorded in
``results/**/manifest.json`` still run.
"""

from __future__ import annotations

import argparse
from typing import Any

from gmloco.deploy import config_cli
from gmloco.deploy.config_cli import Flag, get_value, unflagged, with_values
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
    Flag("--wrench-frames", "wrench_frames"),
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


def field_doc(path: str) -> str:
    """The docstring of the ``G1EvalCfg`` field at ``path`` (empty when it has none)."""
    return config_cli.field_doc(G1EvalCfg, path)


def add_flags(parser: argparse.ArgumentParser, flags: tuple[Flag, ...] = FLAGS) -> None:
    """Add ``flags`` to ``parser``, with the types, defaults (``G1EvalCfg()``), choices and help of their fields."""
    config_cli.add_flags(parser, G1EvalCfg(), flags)


def flag_problem(flag: Flag, value: Any) -> str | None:
    """``FLAG VALUE must be ...`` for a parsed value outside its ``G1EvalCfg`` field's range, else None."""
    return config_cli.flag_problem(G1EvalCfg, flag, value)


def cfg_from_flags(a: argparse.Namespace, base: G1EvalCfg, flags: tuple[Flag, ...] = FLAGS) -> G1EvalCfg:
    """``base`` with the fields of ``flags`` set from parsed arguments (lists become the fields' tuples)."""
    return config_cli.cfg_from_flags(a, base, flags)


def flag_args(cfg: G1EvalCfg, flags: tuple[Flag, ...] = FLAGS) -> list[str]:
    """The arguments of ``flags`` that give back ``cfg``'s values (a switch only when its field is False)."""
    return config_cli.flag_args(cfg, flags)
