# SPDX-License-Identifier: Apache-2.0
"""SIGKILL a pipeline while its second stage runs; the rerun skips the finished stage and loses nothing."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.pipeline_helpers import REPO_ROOT, plain_python_env, run_cli

ARGS = ["tests/toy_pipeline_main.py", "+exp=gm_loco", "+scale=smoke"]


def _wait_for_teacher_done(manifest: Path, proc: subprocess.Popen[str], timeout_s: float = 120.0) -> None:
    """Poll ``manifest.json`` until train_teacher is recorded as done."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()[1]
        if manifest.exists():
            stages = json.loads(manifest.read_text()).get("stages", {})
            if stages.get("train_teacher", {}).get("status") == "done":
                return
        time.sleep(0.1)
    pytest.fail("train_teacher did not finish in time")


@pytest.mark.skipif(sys.platform == "win32", reason="SIGKILL is POSIX")
def test_sigkill_midway_then_resume(tmp_path: Path) -> None:
    """Kill during distill; rerun: teacher skipped with its checkpoint untouched, distill completes."""
    run_dir = tmp_path / "run"
    proc = subprocess.Popen(
        [sys.executable, *ARGS, f"run_dir={run_dir}"],
        cwd=REPO_ROOT,
        env=plain_python_env(TOY_HANG="1"),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        _wait_for_teacher_done(run_dir / "manifest.json", proc)
        time.sleep(0.5)  # distill is now running (it hangs)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
    checkpoint = run_dir / "train_teacher" / "checkpoint.json"
    before = (checkpoint.stat().st_mtime_ns, checkpoint.read_bytes())
    killed = json.loads((run_dir / "manifest.json").read_text())
    assert "distill" not in killed["stages"]  # never recorded as done
    assert not list(run_dir.rglob("*.tmp"))  # atomic writes left no torn files

    res = run_cli([*ARGS, f"run_dir={run_dir}"])
    assert res.returncode == 0, res.stderr
    summary = json.loads((run_dir / "summary.json").read_text())
    statuses = {row["stage"]: row["status"] for row in summary["stages"]}
    assert statuses["train_teacher"] == "skipped"
    assert statuses["distill"] == "done"
    assert (checkpoint.stat().st_mtime_ns, checkpoint.read_bytes()) == before
    student = json.loads((run_dir / "distill" / "student.json").read_text())
    assert student["teacher"] == json.loads(before[1])
    manifest = json.loads((run_dir / "manifest.json").read_text())
    assert len(manifest["invocations"]) == 2
    assert manifest["stages"]["train_teacher"]["invocation"] == 0
    assert manifest["stages"]["distill"]["invocation"] == 1
