# SPDX-License-Identifier: Apache-2.0
"""Quiet runs: library output goes to the run's log file, the console shows one line per stage, summary.md is kept."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from omegaconf import DictConfig

from tests.pipeline_helpers import CALLS, toy_registry, toy_teacher
from workflows.pipeline_report import say, stage_bar
from workflows.pipeline_run import run_pipeline
from workflows.run_summary import SMOKE_NOTE, headline

Compose = Callable[..., DictConfig]

CHATTER = ("python print from a library", "C-level write to fd 1", "C-level write to fd 2", "a library's stderr")
"""What the noisy stage emits through Python's streams and raw descriptors (warnings print to ``sys.stderr``)."""


def _noisy_teacher(cfg: Any) -> dict[str, float]:
    """The toy teacher, plus output through print, raw fds 1 and 2, ``warnings`` and a progress bar."""
    print(CHATTER[0])
    sys.stdout.flush()
    os.write(1, f"{CHATTER[1]}\n".encode())
    os.write(2, f"{CHATTER[2]}\n".encode())
    print(CHATTER[3], file=sys.stderr)
    with stage_bar("toy iterations", 3, "iterations") as update:
        for k in range(3):
            update(k + 1)
    say("  train_teacher: resumed from model_7.pt (iteration 7)")
    return toy_teacher(cfg)


@pytest.fixture
def run_noisy(compose: Compose, tmp_path: Path) -> Callable[[], dict[str, Any]]:
    """Run the pipeline with the noisy toy teacher in ``tmp_path/run``."""
    CALLS.clear()

    def _run() -> dict[str, Any]:
        cfg = compose("+exp=gm_loco", "+scale=smoke", f"run_dir={tmp_path / 'run'}")
        return run_pipeline(cfg, registry=toy_registry(teacher=_noisy_teacher))

    return _run


def test_library_output_goes_to_the_log_and_the_console_stays_short(
    run_noisy: Callable[[], dict[str, Any]], tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """Every kind of library output lands in pipeline.log, none on the console; one console line per stage."""
    run_noisy()
    out, err = capfd.readouterr()
    console = out + err
    log = (tmp_path / "run" / "pipeline.log").read_text()
    for text in CHATTER:
        assert text in log, text
        assert text not in console, text
    lines = [line for line in console.splitlines() if line.strip()]
    stage_lines = [line for line in lines if line.lstrip().startswith(("train_teacher ", "distill ", "export "))]
    assert len(stage_lines) == 3, lines  # the stubbed later stages too: one line each
    assert any("resumed from model_7.pt (iteration 7)" in line for line in lines)
    assert len(lines) <= 14, lines  # header 2 + 6 stages + resume note + smoke note + summary path
    assert "summary:" in console and "smoke scale" in console


def test_summary_md_states_smoke_scale_and_what_each_stage_made(
    run_noisy: Callable[[], dict[str, Any]], tmp_path: Path
) -> None:
    """summary.md names each stage's files and numbers and says plainly that smoke numbers mean nothing."""
    run_noisy()
    text = (tmp_path / "run" / "summary.md").read_text()
    assert SMOKE_NOTE in text
    assert "## train_teacher" in text and "`checkpoint.json`" in text
    assert "| mean reward | 1.5 |" in text
    assert "## export" in text and "not implemented yet" in text


def test_headlines_pick_the_key_numbers() -> None:
    """Hand values: 2 of 3 walks succeed -> 67 %; a missing reward is left out rather than shown as n/a."""
    line = headline("eval_mpm", {"all/num_episodes": 3.0, "all/success_rate": 2 / 3, "all/success_lo95": 0.2,
                                 "all/success_hi95": 0.94, "all/vel_error": 0.123, "all/mean_sinkage": 0.0456})  # fmt: skip
    assert line == ("episodes 3, success rate (95% interval) 67% (20% to 94%), velocity tracking error 0.12 m/s, "
                    "mean sinkage 0.046 m")  # fmt: skip
    assert headline("distill", {"iteration": 2.0, "mean_reward": None, "seconds_per_iteration": 0.5}) == (
        "iteration 2, time per iteration 0.50 s"
    )
    assert headline("custom", {"a": 1.0, "b": "x"}) == "a 1, b x"


def test_stage_helpers_are_silent_outside_a_pipeline(capfd: pytest.CaptureFixture[str]) -> None:
    """A stage function called on its own (as stage tests do) gets a no-op bar."""
    with stage_bar("alone", 2, "episodes") as update:
        update(1)
    out, err = capfd.readouterr()
    assert out == err == ""


def test_training_stage_announces_the_checkpoint_it_resumes_from(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The newest model_<it>.pt is named with its iteration (10 > 3: numeric, not lexical, order); none: silence."""
    from workflows.policy_training import _announce_resume

    _announce_resume("distill", tmp_path)
    assert capsys.readouterr().err == ""
    for it in (3, 10):
        (tmp_path / f"model_{it}.pt").write_bytes(b"")
    _announce_resume("distill", tmp_path)
    assert f"distill: resumed from {tmp_path / 'model_10.pt'} (iteration 10)" in capsys.readouterr().err
