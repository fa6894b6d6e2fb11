# SPDX-License-Identifier: Apache-2.0
"""The ``gmloco`` command: help, unknown subcommands, overrides passed through, a real dispatch."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from workflows import cli, full_pipeline


def test_help_lists_every_subcommand_with_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    """``gmloco --help`` exits 0 and prints one line per subcommand, each with its summary."""
    assert cli.main(["--help"]) == 0
    out = capsys.readouterr().out
    for command in cli.COMMANDS:
        lines = [line for line in out.splitlines() if line.split()[:1] == [command.name]]
        assert len(lines) == 1 and command.summary in lines[0], command.name
    assert {c.name for c in cli.COMMANDS} >= {"run", "train", "distill", "export", "eval-mpm", "ablation", "sweep"}
    assert {c.name for c in cli.COMMANDS} >= {"eval", "mismatch", "gate"}


def test_no_subcommand_prints_help_and_exits_2(capsys: pytest.CaptureFixture[str]) -> None:
    """A bare ``gmloco`` is bad input: the help goes to stderr, exit code 2."""
    assert cli.main([]) == cli.EXIT_BAD_INPUT == 2
    assert "commands:" in capsys.readouterr().err


def test_unknown_subcommand_exits_2_and_names_the_closest(capsys: pytest.CaptureFixture[str]) -> None:
    """``gmloco trian`` exits 2 with one line naming the typo, the closest subcommand and the valid ones."""
    assert cli.main(["trian", "+exp=gm_loco"]) == 2
    err = capsys.readouterr().err
    assert "unknown command 'trian'" in err and "did you mean 'train'" in err and "eval-mpm" in err
    assert err.count("\n") == 1


def test_run_passes_hydra_overrides_through(monkeypatch: pytest.MonkeyPatch) -> None:
    """``gmloco run ARGS`` calls the pipeline's ``main`` with exactly ARGS as its command line."""
    seen: list[list[str]] = []
    monkeypatch.setattr(sys, "argv", ["gmloco"])
    monkeypatch.setattr(full_pipeline, "main", lambda: seen.append(list(sys.argv)))
    args = ["+exp=gm_loco", "stages=[export]", "seed=3", "--cfg", "job"]
    assert cli.main(["run", *args]) == 0
    assert seen == [["gmloco run", *args]]


def test_dispatch_returns_the_target_exit_code(monkeypatch: pytest.MonkeyPatch) -> None:
    """An entry point that returns an exit code (the package CLIs do) hands it back unchanged."""
    monkeypatch.setattr(sys, "argv", ["gmloco"])
    monkeypatch.setattr(full_pipeline, "main", lambda: 3)
    assert cli.main(["run", "+exp=gm_loco"]) == 3


def test_mismatch_help_runs_the_package_command() -> None:
    """``gmloco mismatch --help`` really runs ``gmloco-mismatch``'s parser (exit 0, its options listed)."""
    res = subprocess.run(
        [sys.executable, "-m", "workflows", "mismatch", "--help"],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=Path(__file__).resolve().parents[2],
        check=False,
    )
    assert res.returncode == 0, res.stderr
    assert "--real" in res.stdout and "--out" in res.stdout


def test_console_script_is_installed() -> None:
    """``uv sync`` installs ``gmloco`` beside this Python; its ``--help`` lists the subcommands."""
    script = Path(sys.executable).parent / "gmloco"
    if not script.is_file():
        pytest.skip("no gmloco console script beside this Python (not installed with uv sync)")
    res = subprocess.run([str(script), "--help"], capture_output=True, text=True, timeout=60, check=False)
    assert res.returncode == 0, res.stderr
    assert all(c.name in res.stdout for c in cli.COMMANDS)
