# SPDX-License-Identifier: Apache-2.0
"""scripts/gpu/train_ts_chunk.py and eval_ts.py end to end on CPU at tiny scale (2 envs, 2 iterations).

Teacher chunk -> student chunk (starting from the teacher) -> resumed student chunk -> held-out evaluation, in one
process (later env builds reuse the compiled Warp kernels). Checks the files that come back, the parity of the
exported student with torch (random inputs and a rollout with env resets) and the structure of the summaries; the
numbers themselves are meaningless at this scale.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from types import ModuleType
from typing import Any

import onnx
import pytest

pytestmark = pytest.mark.slow

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts" / "gpu"
TINY = ["--device", "cpu", "--num-envs", "2", "--num-steps-per-env", "8", "--save-interval", "1"]
TINY_CHECKS = ["--check-envs", "2", "--check-steps", "10", "--check-warmup", "2", "--parity-steps", "12"]


def _load(name: str) -> ModuleType:
    """Import a script of scripts/gpu as a module."""
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def chunks(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Run teacher, student and a resumed student chunk; return their summaries and folders."""
    root = tmp_path_factory.mktemp("ts")
    chunk = _load("train_ts_chunk")
    common = [*TINY, *TINY_CHECKS, "--no-held-out", "--runs-root", str(root / "runs"), "--artifacts", str(root / "a")]
    out = {k: root / k for k in ("teacher", "student", "student2")}
    teacher = chunk.main(["--stage", "teacher", "--max-iterations", "2", "--out", str(out["teacher"]), *common])
    student = chunk.main(["--stage", "student", "--max-iterations", "2", "--out", str(out["student"]), *common])
    resumed = chunk.main(["--stage", "student", "--max-iterations", "3", "--out", str(out["student2"]), *common])
    return {"root": root, "out": out, "teacher": teacher, "student": student, "resumed": resumed}


def test_teacher_chunk_writes_checkpoint_summary_and_vae_curves(chunks: dict[str, Any]) -> None:
    """Teacher: checkpoint + summary with the VAE loss curves and the decoded-eta check; no ONNX (not deployed)."""
    out, summary = chunks["out"]["teacher"], chunks["teacher"]
    assert (out / "checkpoint.pt").exists() and not (out / "policy.onnx").exists()
    assert json.loads((out / "summary.json").read_text())["stage"] == "teacher"
    assert summary["metrics"]["iteration"] == 2.0
    curve = summary["curve"]
    assert curve["iteration"] == [0.0, 1.0]
    for name in ("loss_eta_reconstruction", "loss_latent_kl", "loss_eta_r2", "mean_reward", "mean_episode_length"):
        assert len(curve[name]) == 2, name
    assert {"dr_eta_r2_teacher", "dr_eta_mae_teacher"} <= summary["checks"].keys()


def test_student_chunk_starts_from_the_teacher_and_exports_a_matching_onnx(chunks: dict[str, Any]) -> None:
    """Student: starts from the teacher's checkpoint, exports policy.onnx with metadata; ONNX = torch to 1e-5."""
    out, summary = chunks["out"]["student"], chunks["student"]
    assert summary["teacher_checkpoint"].endswith("model_2.pt")
    checks = summary["checks"]
    assert checks["onnx_max_abs_diff"] <= 1e-5
    assert checks["rollout_onnx_max_abs_diff"] <= 1e-5 and checks["rollout_eta_max_abs_diff"] <= 1e-5
    assert checks["rollout_resets"] >= 1  # the history padding after a reset was compared too
    assert {"dr_eta_r2_student", "dr_eta_r2_teacher", "dr_student_teacher_action_mse"} <= checks.keys()
    model = onnx.load(str(out / "policy.onnx"))
    assert [i.name for i in model.graph.input] == ["obs", "history"]
    assert [o.name for o in model.graph.output] == ["actions", "latent", "eta"]
    meta = json.loads((out / "policy.json").read_text())
    assert meta["observation"]["history_length"] == 50 and meta["latent_dim"] == 16
    assert meta["observation"]["history_order"] == "oldest_first" and len(meta["joints"]["names"]) == 29
    for name in ("loss_distill_action", "loss_distill_latent", "loss_distill_decoded", "loss_eta_r2", "loss_w_ppo"):
        assert name in summary["curve"], name


def test_student_chunk_resumes_from_its_own_checkpoint(chunks: dict[str, Any]) -> None:
    """A second student call continues at iteration 2 (its checkpoint carries the teacher) up to 3."""
    resumed = chunks["resumed"]
    assert resumed["teacher_checkpoint"] is None
    assert resumed["metrics"]["resumed_from_iteration"] == 2.0 and resumed["metrics"]["iteration"] == 3.0


def test_eval_ts_scores_held_out_materials_presets_baseline_and_adaptation(chunks: dict[str, Any]) -> None:
    """eval_ts: eta R^2 per group for student and teacher, walking metrics next to the PPO baseline, the figure."""
    baseline = Path(__file__).resolve().parents[2] / "artifacts" / "ppo_rft3d" / "policy.onnx"
    out = chunks["root"] / "eval"
    args = ["--student", str(chunks["out"]["student2"] / "checkpoint.pt"), "--device", "cpu", "--out", str(out)]
    args += ["--held-out-grid", "2,1", "--presets", "dry_sand,poppy_seed", "--repeats", "1", "--duration-s", "0.3"]
    args += ["--warmup-s", "0.1", "--adaptation-duration-s", "0.4", "--adaptation-edges", "0.005,0.01"]
    args += ["--baseline", str(baseline) if baseline.exists() else "none"]
    summary = _load("eval_ts").main(args)
    metrics = summary["metrics"]
    for group in ("held_out", "presets", "all"):
        for key in ("eta_r2_student", "eta_r2_teacher", "eta_mae_student", "student_teacher_action_mse"):
            assert f"{group}/{key}" in metrics, (group, key)
        assert metrics[f"{group}/num_envs"] == 2.0 if group != "all" else 4.0
    assert [r["group"] for r in summary["materials"]] == ["held_out", "held_out", "presets", "presets"]
    assert [r["material"] for r in summary["adaptation"]] == ["basalt", "dry_sand", "poppy_seed"]
    if baseline.exists():
        cells = [r["cell"] for r in summary["comparison"]]
        assert cells[2:] == ["dry_sand/v1", "poppy_seed/v1", "held_out", "presets", "all"]
        assert cells[0].startswith("held_out_rho") and summary["comparison"][-1]["baseline_success_rate"] is not None
    for name in ("summary.json", "materials.csv", "adaptation.png", "adaptation_env0.json"):
        assert (out / name).exists(), name
