# SPDX-License-Identifier: Apache-2.0
"""Real stages under the runner: analyze_logs skipped on rerun and rerun with force; a time-boxed train stage resumes."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from omegaconf import DictConfig

from tests.pipeline_helpers import REPO_ROOT
from workflows.pipeline_run import EXIT_INCOMPLETE, EXIT_OK, run_pipeline
from workflows.run_dir import read_json
from workflows.stage_runner import PipelineConfigError

SAMPLE_LOGS = sorted((REPO_ROOT / "packages" / "deploy" / "data" / "sample_logs").glob("*.mcap"))
"""The committed sample recordings, analyze_logs' default input."""


@pytest.fixture
def run_logs(compose: Callable[..., DictConfig], tmp_path: Path) -> Callable[..., dict[str, Any]]:
    """Return ``run(*overrides)``: the analyze_logs stage alone (real), in ``tmp_path/run``."""

    def _run(*overrides: str) -> dict[str, Any]:
        cfg = compose(
            "+exp=gm_loco", "+scale=smoke", f"run_dir={tmp_path / 'run'}", "stages=[analyze_logs]", *overrides
        )
        summary = run_pipeline(cfg)
        assert summary["exit_code"] == EXIT_OK
        return next(row for row in summary["stages"] if row["stage"] == "analyze_logs")

    return _run


def test_real_stage_is_skipped_on_rerun_and_rerun_with_force(
    run_logs: Callable[..., dict[str, Any]], tmp_path: Path
) -> None:
    """First run: done with real outputs; same config: skipped, files untouched; force: done again, rewritten."""
    first = run_logs("analyze_logs.figures=false")
    assert first["status"] == "done" and first["metrics"]["recordings"] == len(SAMPLE_LOGS)
    table = tmp_path / "run" / "analyze_logs" / "summary.md"
    assert "g1_scripted_rigid_staircase.mcap" in table.read_text()
    stamp = table.stat().st_mtime_ns

    again = run_logs("analyze_logs.figures=false", "max_minutes=3")  # a volatile key does not matter
    assert again["status"] == "skipped" and again["metrics"] == first["metrics"]
    assert table.stat().st_mtime_ns == stamp

    forced = run_logs("analyze_logs.figures=false", "force=[analyze_logs]")
    assert forced["status"] == "done" and table.stat().st_mtime_ns > stamp
    manifest = read_json(tmp_path / "run" / "manifest.json")
    assert manifest["stages"]["analyze_logs"]["invocation"] == 2


def test_changed_input_reruns_the_real_stage_only_when_forced(
    run_logs: Callable[..., dict[str, Any]], tmp_path: Path
) -> None:
    """One recording instead of all changes analyze_logs' config: refused, results kept; forced, it reruns.

    With ``force=[analyze_logs]`` it analyzes just that one recording.
    """
    assert run_logs("analyze_logs.figures=false")["status"] == "done"
    table = tmp_path / "run" / "analyze_logs" / "summary.md"
    before = table.read_text()
    one = "${paths.sample_logs_dir}/g1_scripted_rigid_no_odometry.mcap"
    with pytest.raises(PipelineConfigError, match=r"force=\[analyze_logs\]"):
        run_logs("analyze_logs.figures=false", f"analyze_logs.inputs=[{one}]")
    assert table.read_text() == before
    row = run_logs("analyze_logs.figures=false", f"analyze_logs.inputs=[{one}]", "force=[analyze_logs]")
    assert row["status"] == "done" and row["metrics"]["recordings"] == 1


@pytest.mark.slow
def test_time_boxed_training_stage_resumes_from_its_checkpoint(
    compose: Callable[..., DictConfig], tmp_path: Path
) -> None:
    """A time-boxed ``+exp=ppo_rigid`` train stage stops incomplete with a checkpoint; the rerun continues from it.

    The tiny time box stops it after one iteration (exit 3, ``model_1.pt``); the rerun loads that checkpoint and runs
    iteration 2 only. About 1 min on 2 CPU cores.
    """

    def _run(*overrides: str) -> dict[str, Any]:
        cfg = compose("+exp=ppo_rigid", "+scale=smoke", f"run_dir={tmp_path}", "device=cpu", *overrides)
        summary = run_pipeline(cfg)
        return summary | {"row": summary["stages"][0]}

    stopped = _run("max_minutes=0.01")
    assert stopped["exit_code"] == EXIT_INCOMPLETE and stopped["row"]["status"] == "incomplete"
    assert "iteration 1 of 2" in stopped["row"]["message"]
    assert (tmp_path / "train_teacher" / "model_1.pt").is_file()
    done = _run()
    assert done["exit_code"] == EXIT_OK and done["row"]["status"] == "done"
    metrics = done["row"]["metrics"]
    assert metrics["resumed_from_iteration"] == 1 and metrics["iteration"] == 2 and metrics["iterations_done"] == 1
    assert (tmp_path / "train_teacher" / "policy.onnx").is_file()
