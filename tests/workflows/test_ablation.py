# SPDX-License-Identifier: Apache-2.0
"""The contact-model ablation (``workflows/ablation.py``): collect or train policies, evaluate, compare.

Most tests replace ``evaluate_policy`` by a fake whose metrics are a known function of the policy, so the
collection, caching and report logic runs in seconds. Two ``slow`` tests run the command for real on the CPU: one
evaluates a committed policy on one short cell (~1 min on 2 cores), one trains two experiments at smoke scale first.
"""

from __future__ import annotations

import csv
import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from omegaconf import DictConfig

from tests.pipeline_helpers import REPO_ROOT, run_cli
from workflows import ablation
from workflows.stage_runner import PipelineConfigError

COMMITTED = REPO_ROOT / "artifacts" / "ppo_rft3d"
"""A committed vanilla-PPO artifact (policy.onnx + metrics.json)."""
needs_artifact = pytest.mark.skipif(not (COMMITTED / "policy.onnx").is_file(), reason="no committed ppo_rft3d policy")


class FakeEvaluate:
    """Stand-in for ``evaluate_policy``: success 1 - speed / 10 and vel_error = speed / 2 for every cell."""

    def __init__(self, fail_on: str | None = None) -> None:
        """``fail_on``: a substring of the policy path for which evaluation raises."""
        self.calls: list[Any] = []
        self.fail_on = fail_on

    def __call__(self, cfg: Any) -> dict[str, float]:
        """Record the EvalCfg and return per-cell and ``all`` metrics."""
        self.calls.append(cfg)
        if self.fail_on and self.fail_on in cfg.policy_path:
            raise RuntimeError("simulated evaluation error")
        out: dict[str, float] = {}
        for m in cfg.materials:
            for s in cfg.speeds:
                cell = f"{m}/v{s:g}"
                out |= {f"{cell}/success_rate": 1 - s / 10, f"{cell}/vel_error": s / 2}
                out |= {f"{cell}/yaw_rate_error": 0.1, f"{cell}/num_envs": float(cfg.repeats)}
        mean_speed = sum(cfg.speeds) / len(cfg.speeds)
        out |= {"all/success_rate": 1 - mean_speed / 10, "all/vel_error": mean_speed / 2}
        out |= {"all/yaw_rate_error": 0.1, "all/num_envs": float(cfg.repeats * len(cfg.materials) * len(cfg.speeds))}
        return out


@pytest.fixture
def fake_evaluate(monkeypatch: pytest.MonkeyPatch) -> Callable[..., FakeEvaluate]:
    """Install a :class:`FakeEvaluate` as ``gmloco.train.evaluate_policy``."""
    import gmloco.train

    def install(**kwargs: Any) -> FakeEvaluate:
        fake = FakeEvaluate(**kwargs)
        monkeypatch.setattr(gmloco.train, "evaluate_policy", fake, raising=False)
        return fake

    return install


@pytest.fixture
def artifacts(tmp_path: Path) -> Path:
    """An artifacts folder holding ppo_rft3d and ppo_rigid (copies of the committed ppo_rft3d files) only."""
    root = tmp_path / "artifacts"
    for exp in ("ppo_rft3d", "ppo_rigid"):
        (root / exp).mkdir(parents=True)
        for name in ("policy.onnx", "metrics.json"):
            shutil.copy(COMMITTED / name, root / exp / name)
    return root


def _cfg(compose: Callable[..., DictConfig], run_dir: Path, artifacts: Path, *extra: str) -> DictConfig:
    """The contact-model ablation at smoke scale on ``artifacts``."""
    return compose(
        "+exp=ppo_rft3d",
        "+ablation=contact_models",
        "+scale=smoke",
        "device=cpu",
        "tracking.wandb=disabled",
        f"run_dir={run_dir}",
        f"ablation.artifacts_dir={artifacts}",
        *extra,
    )


@needs_artifact
def test_collect_artifact_reads_the_policy_or_reports_it_missing(
    compose: Callable[..., DictConfig], artifacts: Path, tmp_path: Path
) -> None:
    """A committed policy gives its hash, training contact model and iteration; an absent one is missing."""
    cfg = _cfg(compose, tmp_path / "run", artifacts)
    arm = ablation.collect_artifact(cfg, "ppo_rft3d")
    metrics = json.loads((COMMITTED / "metrics.json").read_text())
    assert arm.status == "pending" and arm.trained_on == "rft3d" and arm.iteration == metrics["iteration"]
    assert arm.sha256 == ablation._sha256(COMMITTED / "policy.onnx")
    missing = ablation.collect_artifact(cfg, "ppo_cone_multi")
    assert missing.status == "missing" and "ppo_cone_multi/policy.onnx does not exist" in missing.reason
    assert missing.policy is None and missing.metrics == {}


@needs_artifact
def test_ablation_reports_missing_experiments_and_never_fills_them(
    compose: Callable[..., DictConfig], fake_evaluate: Callable[..., FakeEvaluate], artifacts: Path, tmp_path: Path
) -> None:
    """2 of 4 policies exist: 2 evaluated (one ground, smoke settings), 2 missing rows without numbers; exit 0."""
    fake = fake_evaluate()
    summary = ablation.run_ablation(_cfg(compose, tmp_path, artifacts), arm_overrides=[])
    assert summary["exit_code"] == 0
    status = {a["exp"]: a["status"] for a in summary["arms"]}
    assert status == {
        "ppo_rft3d": "evaluated",
        "ppo_heuristic_rft": "missing",
        "ppo_cone_multi": "missing",
        "ppo_rigid": "evaluated",
    }
    assert [Path(c.policy_path).parent.name for c in fake.calls] == ["ppo_rft3d", "ppo_rigid"]
    for call in fake.calls:  # every policy on the same 3D-RFT ground, smoke-scale repeats and duration
        assert (call.contact_model, call.repeats, call.duration_s) == ("rft3d", 1, 0.5)
        assert call.materials == ("dry_sand", "poppy_seed") and call.speeds == (0.5, 1.0)
    rows = list(csv.DictReader((tmp_path / "ablation.csv").open()))
    assert len(rows) == 2 * 5 + 2  # 4 cells + all per evaluated exp, one row per missing exp
    for row in rows:
        if row["status"] == "missing":
            assert row["success_rate"] == row["vel_error"] == "" and "does not exist" in row["note"]
        elif row["cell"] != "all":
            speed = float(row["cell"].split("/v")[1])
            assert float(row["vel_error"]) == pytest.approx(speed / 2)
    md = (tmp_path / "ablation.md").read_text()
    assert "| ppo_cone_multi | - | - | missing |  | - | - | - | - |" in md and "**ppo_heuristic_rft** missing" in md
    assert (tmp_path / "figures" / "ablation.png").stat().st_size > 10_000
    assert (tmp_path / "config.yaml").is_file() and (tmp_path / "git").is_dir()
    # A rerun reuses eval/<exp>.json (same policy, same settings); changed settings evaluate again.
    ablation.run_ablation(_cfg(compose, tmp_path, artifacts), arm_overrides=[])
    assert len(fake.calls) == 2
    ablation.run_ablation(_cfg(compose, tmp_path, artifacts, "ablation.speeds=[1.0]"), arm_overrides=[])
    assert len(fake.calls) == 4


@needs_artifact
def test_a_failed_evaluation_is_reported_and_the_others_still_run(
    compose: Callable[..., DictConfig], fake_evaluate: Callable[..., FakeEvaluate], artifacts: Path, tmp_path: Path
) -> None:
    """An evaluation error marks that experiment failed (exit 1); the next one is still evaluated."""
    fake_evaluate(fail_on="ppo_rft3d")
    summary = ablation.run_ablation(_cfg(compose, tmp_path, artifacts), arm_overrides=[])
    arms = {a["exp"]: a for a in summary["arms"]}
    assert summary["exit_code"] == 1
    assert arms["ppo_rft3d"]["status"] == "failed" and "simulated evaluation error" in arms["ppo_rft3d"]["reason"]
    assert arms["ppo_rigid"]["status"] == "evaluated"


def test_unknown_experiment_is_refused(compose: Callable[..., DictConfig], tmp_path: Path) -> None:
    """``ablation.exps`` naming no conf/exp file is bad input naming the key."""
    cfg = _cfg(compose, tmp_path, tmp_path, "ablation.exps=[ppo_rft3d,ppo_sand]")
    with pytest.raises(PipelineConfigError) as info:
        ablation.run_ablation(cfg, arm_overrides=[])
    assert info.value.key == "ablation.exps" and "ppo_sand" in str(info.value)


def test_markdown_table_formats_numbers_and_missing_cells() -> None:
    """Floats with 3 significant digits, None as '-', reasons listed under the table."""
    settings = {"contact_model": "rft3d", "terrain": "flat", "materials": ["dry_sand"], "speeds": [1.0]}
    settings |= {"repeats": 2, "duration_s": 10.0, "seed": 0}
    arm = ablation.Arm("ppo_rft3d", "evaluated", trained_on="rft3d", iteration=542.0)
    arm.metrics = {
        f"{c}/{m}": v
        for c in ("dry_sand/v1", "all")
        for m, v in zip(ablation.METRICS, (0.5, 0.12345, 0.1, 2.0), strict=True)
    }
    rows = ablation.table_rows([arm, ablation.Arm("ppo_rigid", "missing", "no policy")], settings)
    assert [r["cell"] for r in rows] == ["dry_sand/v1", "all", ""]
    md = ablation.markdown_table(rows, settings, {"scale": "full", "git_commit": "abc"})
    assert "| ppo_rft3d | rft3d | 542 | evaluated | dry_sand/v1 | 0.5 | 0.123 | 0.1 | 2 |" in md
    assert "| ppo_rigid | - | - | missing |  | - | - | - | - |" in md and "- **ppo_rigid** missing: no policy" in md


@pytest.mark.slow
@needs_artifact
def test_ablation_command_evaluates_a_committed_policy_on_cpu(tmp_path: Path, artifacts: Path) -> None:
    """``ablation.py +ablation=contact_models`` for real: one 0.2 s cell, one committed policy, one missing."""
    args = [
        "workflows/ablation.py",
        "+ablation=contact_models",
        f"run_dir={tmp_path / 'run'}",
        f"ablation.artifacts_dir={artifacts}",
        "ablation.exps=[ppo_rft3d,ppo_cone_multi]",
        "ablation.materials=[dry_sand]",
        "ablation.speeds=[1.0]",
        "ablation.smoke_duration_s=0.2",
        "device=cpu",
    ]
    res = run_cli(args, timeout=600)
    assert res.returncode == 0, res.stderr[-4000:]
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    arms = {a["exp"]: a for a in summary["arms"]}
    assert summary["settings"]["duration_s"] == 0.2 and arms["ppo_cone_multi"]["status"] == "missing"
    metrics = arms["ppo_rft3d"]["metrics"]
    assert arms["ppo_rft3d"]["status"] == "evaluated" and metrics["all/num_envs"] == 1.0
    assert 0.0 <= metrics["all/success_rate"] <= 1.0 and metrics["all/vel_error"] >= 0.0


@pytest.mark.slow
def test_ablation_trains_two_experiments_at_smoke_scale(tmp_path: Path) -> None:
    """``ablation.source=train``: each experiment's train stage runs (2 iterations), then its policy is evaluated."""
    args = ["workflows/ablation.py", "+ablation=contact_models", "ablation.source=train", f"run_dir={tmp_path}"]
    args += ["ablation.exps=[ppo_cone_multi,ppo_rigid]", "ablation.speeds=[1.0]", "device=cpu"]
    res = run_cli(args, timeout=1500)
    assert res.returncode == 0, res.stderr[-4000:]
    summary = json.loads((tmp_path / "summary.json").read_text())
    for arm in summary["arms"]:
        assert arm["status"] == "evaluated" and arm["iteration"] == 2.0
        assert arm["trained_on"] == arm["exp"].removeprefix("ppo_")
        assert (tmp_path / "train" / arm["exp"] / "train_teacher" / "policy.onnx").is_file()


@needs_artifact
def test_without_matplotlib_the_tables_are_written_and_the_figure_is_named_missing(
    compose: Callable[..., DictConfig],
    fake_evaluate: Callable[..., FakeEvaluate],
    artifacts: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """On a machine without matplotlib (the GPU image may lack it) the report says so instead of failing."""
    import sys

    fake_evaluate()
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # makes ``import matplotlib`` raise ImportError
    summary = ablation.run_ablation(_cfg(compose, tmp_path, artifacts), arm_overrides=[])
    assert summary["exit_code"] == 0 and summary["figure"].startswith("not drawn: matplotlib is not installed")
    assert (tmp_path / "ablation.md").is_file() and not (tmp_path / "figures" / "ablation.png").exists()


def test_eval_cells_are_the_package_material_cells(compose: Callable[..., DictConfig], tmp_path: Path) -> None:
    """``ablation.<field>`` of ``MaterialCellsCfg`` (failure rules and floor too) reaches the evaluation and its key."""
    from gmloco.train.evaluation_cells import MaterialCellsCfg

    cfg = _cfg(compose, tmp_path, tmp_path, "ablation.max_tilt=0.5", "ablation.floor.depth_range=[0.2,0.2]")
    cells = ablation.eval_cells(cfg)
    assert isinstance(cells, MaterialCellsCfg) and cells.max_tilt == 0.5 and cells.floor.depth_range == (0.2, 0.2)
    assert (cells.repeats, cells.duration_s, cells.speeds) == (1, 0.5, (0.5, 1.0))  # smoke sizes
    settings = ablation.eval_settings(cfg)
    assert settings["max_tilt"] == 0.5 and settings["floor"]["depth_range"] == [0.2, 0.2]
    assert settings["contact_model"] == "rft3d" and settings["materials"] == ["dry_sand", "poppy_seed"]
