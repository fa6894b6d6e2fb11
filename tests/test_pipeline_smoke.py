# SPDX-License-Identifier: Apache-2.0
"""The main command runs every implemented stage for real (smoke scale on a CPU); each stage runs alone.

The end-to-end run takes 1.5-3 min on 2 CPU cores (plus the one-time MuJoCo Warp compile), so it is marked
``slow``: ``.ci/run`` runs the same main command verbatim right after the tests, so CI still proves it every time.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.pipeline_helpers import REPO_ROOT, run_cli
from workflows.stage_registry import stage_names

SAMPLE_LOGS = sorted((REPO_ROOT / "packages" / "deploy" / "data" / "sample_logs").glob("*.mcap"))
"""The committed sample recordings, analyze_logs' default input."""
OK_STATUSES = {"done", "not_implemented", "blocked"}
"""What a healthy run may report (nothing failed, nothing faked)."""
REAL_STAGES = ("train_teacher", "distill", "export", "eval_mpm", "analyze_logs", "mismatch")
"""Stages with a real implementation: each must be done at smoke scale."""
STAGE_FILES = {
    "train_teacher": ["model_2.pt", "train_cfg.json"],
    "distill": ["model_2.pt", "train_cfg.json"],
    "export": ["policy.onnx", "policy.json"],
    "eval_mpm": ["episodes.jsonl", "summary.json"],
    "analyze_logs": ["summary.md", "summary.json", "tracking.csv"],
    "mismatch": ["report.json", "report.md", "config_patch.json"],
}
"""Files each real stage must leave in its folder (besides ``metrics.json``)."""


def _cuda() -> bool:
    """Whether the smoke scale is not chosen automatically on this machine."""
    from workflows.stage_runner import resolve_device

    return resolve_device("auto") != "cpu"


@pytest.mark.slow
@pytest.mark.skipif(_cuda(), reason="the main command runs full scale on a GPU machine")
def test_main_command_runs_every_implemented_stage(tmp_path: Path) -> None:
    """``full_pipeline.py +exp=gm_loco``: exit 0; every stage done with its files."""
    res = run_cli(["workflows/full_pipeline.py", "+exp=gm_loco", f"run_dir={tmp_path}"], timeout=1200)
    assert res.returncode == 0, res.stderr[-4000:]
    assert "SMOKE SCALE" in res.stderr and f"summary: {tmp_path / 'summary.md'}" in res.stderr
    # quiet console: library output (mjlab tables, Warp's banner) is in the log file, not on the console
    console = [line for line in (res.stdout + res.stderr).splitlines() if line.strip()]
    assert len(console) <= 20, console
    log = (tmp_path / "full_pipeline.log").read_text()
    assert "Warp" in log and "Warp" not in res.stderr
    assert "not meaningful about the policy" in (tmp_path / "summary.md").read_text()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["scale"] == "smoke"
    rows = {row["stage"]: row for row in summary["stages"]}
    assert list(rows) == stage_names()
    for name in REAL_STAGES:
        assert rows[name]["status"] == "done", rows[name]
        for rel in ["metrics.json", *STAGE_FILES[name]]:
            assert (tmp_path / name / rel).is_file(), f"{name}/{rel}"
    assert rows["eval_mpm"]["metrics"]["all/num_episodes"] >= 1
    export = rows["export"]["metrics"]
    assert export["onnx_max_abs_diff"] <= 1e-5 and export["rollout_onnx_max_abs_diff"] <= 1e-5
    assert rows["train_teacher"]["metrics"]["iteration"] == 2 and rows["distill"]["metrics"]["iteration"] == 2
    # the sample recordings plus the MPM evaluation's own (one per episode group, found in the run directory)
    eval_mcaps = list((tmp_path / "eval_mpm").rglob("*.mcap"))
    assert len(eval_mcaps) == 1
    assert rows["analyze_logs"]["metrics"]["recordings"] == len(SAMPLE_LOGS) + len(eval_mcaps)
    assert rows["mismatch"]["metrics"]["verdict"] in {"no_mismatch", "explained", "unexplained", "invalid_input"}


def test_stage_runs_alone_with_plain_python(tmp_path: Path) -> None:
    """``python workflows/export.py`` with PYTHONPATH only runs that stage: blocked without a student."""
    res = run_cli(["workflows/export.py", "+exp=gm_loco", f"run_dir={tmp_path}", "max_minutes=5"])
    assert res.returncode == 0, res.stderr
    summary = json.loads((tmp_path / "summary.json").read_text())
    statuses = {row["stage"]: row["status"] for row in summary["stages"]}
    assert statuses.pop("export") == "blocked"
    assert set(statuses.values()) == {"disabled"}
    assert (tmp_path / "export.log").exists()  # Hydra's job log carries the stage's name


def test_train_entry_prints_the_ablation_config() -> None:
    """``python workflows/train.py +exp=ppo_rigid --cfg job``: the train stage alone, vanilla PPO on rigid ground."""
    res = run_cli(["workflows/train.py", "+exp=ppo_rigid", "--cfg", "job"])
    assert res.returncode == 0, res.stderr
    for line in ("algorithm: ppo", "contact_model: rigid", "- train_teacher"):
        assert line in res.stdout
