# SPDX-License-Identifier: Apache-2.0
"""The ``gmloco`` command: one front door to the workflows and to the packages' command lines.

Usage::

    gmloco run +exp=gm_loco                 # the whole pipeline (python workflows/full_pipeline.py +exp=gm_loco)
    gmloco train +exp=ppo_rft3d             # one stage alone, in a run directory
    gmloco mismatch --real robot.mcap ...   # a package's command line
    gmloco <command> --help                 # that command's own help

Each subcommand hands the rest of the command line, unchanged, to an existing entry point: the Hydra workflows take
overrides (``key=value``, ``+exp=NAME``), the package commands their own options. The target is imported only when
its subcommand runs, so ``gmloco --help`` loads no dependency. Exit codes are the target's; an unknown subcommand
exits with 2.
"""

from __future__ import annotations

import difflib
import importlib
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TextIO

__all__ = ["COMMANDS", "EXIT_BAD_INPUT", "PROG", "Command", "main"]

PROG = "gmloco"
"""The command's name."""
EXIT_BAD_INPUT = 2
"""Exit code for an unknown or missing subcommand."""


@dataclass(frozen=True)
class Command:
    """One subcommand and the entry point it runs."""

    name: str
    """Subcommand as typed after ``gmloco``."""
    target: str
    """Entry point as ``module:function``; the function reads ``sys.argv`` and returns None or an exit code."""
    summary: str
    """One line for ``gmloco --help``."""


COMMANDS: tuple[Command, ...] = (
    Command("run", "workflows.full_pipeline:main", "whole pipeline, train_teacher to mismatch (+exp=gm_loco; Hydra)"),
    Command("train", "workflows.train:main", "train stage alone: PPO baselines, VAE teacher, jumping (Hydra)"),
    Command("distill", "workflows.distill:main", "distill stage alone: TCN student from the frozen teacher (Hydra)"),
    Command("export", "workflows.export:main", "export stage alone: ONNX student with deploy metadata (Hydra)"),
    Command("eval-mpm", "workflows.eval_mpm:main", "eval_mpm stage alone: the exported policy on MPM sand (Hydra)"),
    Command("ablation", "workflows.ablation:main", "contact-model ablation (+ablation=contact_models; Hydra)"),
    Command("sweep", "workflows.sweep:main", "Optuna sweep over the train stage (+sweep=optuna_teacher; Hydra)"),
    Command("eval", "gmloco.eval.g1.cli:main", "G1 evaluation on MPM sand from flags (python -m gmloco.eval.g1.cli)"),
    Command("mismatch", "gmloco.deploy.mismatch.cli:main", "sim-vs-real mismatch discovery on a recording"),
    Command("gate", "gmloco.train.gate.__main__:main", "training gate: a policy scored in the training simulator"),
)
"""Every subcommand, in the order ``gmloco --help`` lists them."""


def _help_text() -> str:
    """Usage, one line per subcommand, and where each command's own options are."""
    width = max(len(c.name) for c in COMMANDS)
    lines = [f"  {c.name:<{width}}  {c.summary}" for c in COMMANDS]
    return "\n".join(
        [
            f"usage: {PROG} <command> [args ...]",
            "",
            "Humanoid locomotion on granular media: training, evaluation, deployment checks.",
            "",
            "commands:",
            *lines,
            "",
            f"'{PROG} <command> --help' shows a command's own options; Hydra commands take overrides (key=value).",
        ]
    )


def _print_help(stream: TextIO) -> None:
    """Write the help text to ``stream``."""
    print(_help_text(), file=stream)


def _unknown(name: str) -> int:
    """Say that ``name`` is no subcommand (with the closest one, if any); return the bad-input exit code."""
    names = [c.name for c in COMMANDS]
    close = difflib.get_close_matches(name, names, n=1)
    hint = f" (did you mean '{close[0]}'?)" if close else ""
    print(
        f"{PROG}: error: unknown command '{name}'{hint}. Commands: {', '.join(names)}. See '{PROG} --help'.",
        file=sys.stderr,
    )
    return EXIT_BAD_INPUT


def _dispatch(command: Command, args: Sequence[str]) -> int:
    """Run ``command``'s entry point with ``args`` as its command line; return its exit code."""
    module_name, func_name = command.target.split(":")
    func = getattr(importlib.import_module(module_name), func_name)
    sys.argv = [f"{PROG} {command.name}", *args]
    code = func()
    return code if isinstance(code, int) else 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the subcommand named by ``argv[0]`` (default: ``sys.argv[1:]``) with the rest; return the exit code."""
    args = list(sys.argv[1:] if argv is None else argv)
    if not args:
        _print_help(sys.stderr)
        return EXIT_BAD_INPUT
    if args[0] in ("-h", "--help"):
        _print_help(sys.stdout)
        return 0
    command = next((c for c in COMMANDS if c.name == args[0]), None)
    if command is None:
        return _unknown(args[0])
    return _dispatch(command, args[1:])


if __name__ == "__main__":
    sys.exit(main())
