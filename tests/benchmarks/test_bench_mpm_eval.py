# SPDX-License-Identifier: Apache-2.0
"""benchmarks/gpu/bench_mpm_eval.py: case order, the convergence verdicts on hand-made results, a tiny CPU run."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

SCRIPTS = Path(__file__).resolve().parents[2] / "benchmarks" / "gpu"
POLICY = Path(__file__).resolve().parents[2] / "artifacts" / "ppo_rft3d" / "policy.onnx"


def _load() -> ModuleType:
    """Import the script as a module."""
    spec = importlib.util.spec_from_file_location("bench_mpm_eval", SCRIPTS / "bench_mpm_eval.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_cases_put_the_coarse_throughput_cases_first() -> None:
    """Coarsest window, multi and naive first; finer voxels next; the standing checks last."""
    bench = _load()
    args = bench.replace(bench.Namespace(), voxels=[0.03, 0.05, 0.04], robots=8, naive_voxels=None, iters_check=250)
    keys = [bench._key(c) for c in bench._cases(args)]
    assert keys[:3] == ["window/v0.05/r1", "multi/v0.05/r8", "naive/v0.05/r1"]
    assert keys[3:7] == ["multi/v0.04/r8", "window/v0.04/r1", "multi/v0.03/r8", "window/v0.03/r1"]
    assert keys[7] == "multi/v0.05/r8/it250"
    assert keys[8:] == ["stand/v0.05/r4", "stand/v0.04/r4", "stand/v0.03/r4"]


def test_convergence_verdicts() -> None:
    """Against the finest voxel (3 cm): 4 cm within 15 % accepted, 5 cm sinking 50 % deeper rejected.

    Sinkage bounds: max(0.15 x 20 mm, 0.25 x 15 mm) = 3.75 mm; 4 cm differs by 2 mm, 5 cm by 10 mm.
    """
    bench = _load()
    res = {
        f"multi/v{v}": {"mode": "multi", "voxel": v, "sinkage_m": s, "pelvis_z_m": 0.75, "vx_mps": 0.9}
        for v, s in ((0.03, 0.020), (0.04, 0.022), (0.05, 0.030))
    }
    rows = bench._convergence(res, 0.15)["multi"]["rows"]
    assert [r["voxel"] for r in rows] == [0.03, 0.04, 0.05]
    assert [r["accepted"] for r in rows] == [None, True, False]
    assert rows[2]["sinkage_m_change"] == pytest.approx(0.010)
    # the same numbers with a foot on the floor (14 cm of a 15 cm bed) give no acceptance
    res["multi/v0.04"].update(max_sinkage_m=0.14, depth_m=0.15)
    rows = bench._convergence(res, 0.15)["multi"]["rows"]
    assert rows[1]["floor_reached"] and rows[1]["accepted"] is False


@pytest.mark.slow
def test_tiny_cpu_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """10 cm / 8 cm voxels, 2 robots, 4 frames on CPU: all 8 cases finish and bench.json holds their numbers."""
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    bench = _load()
    argv = ["bench", "--out", str(tmp_path), "--policy", str(POLICY), "--voxels", "0.1", "0.08", "--robots", "2",
            "--frames", "4", "--stand-frames", "4", "--device", "cpu", "--window-length", "0.6",
            "--window-width", "0.4", "--max-minutes", "8", "--iters-check", "75"]  # fmt: skip
    monkeypatch.setattr(sys, "argv", argv)
    bench.main()
    doc = json.loads((tmp_path / "bench.json").read_text())
    res = doc["results"]
    assert len(res) == 8 and all("frames_per_s" in r for r in res.values()), res
    assert set(doc["convergence"]["iterations"]) >= {"sinkage_m_change", "iterations"}
    assert res["naive/v0.1/r1"]["particles"] > res["window/v0.1/r1"]["particles"]
    assert res["multi/v0.1/r2"]["particles"] == 2 * res["window/v0.1/r1"]["particles"]
    assert all(r["through_floor"] == 0 for r in res.values()), res  # on the CPU the robots stay above the floor
    assert set(doc["convergence"]) == {"multi", "stand", "iterations"}


def _partial_h100_results() -> dict[str, dict[str, Any]]:
    """The shape of the H100 run's bench.json (commit 9af447a) when ``_convergence`` raised ``KeyError: 'sinkage_m'``.

    Five measured cases (numbers rounded from ``results/mpm_eval/bench_h100.json``; no ``capture_error`` key, which
    that commit did not write) and the case the time box skipped: ``{**case, "skipped": ...}``, no metrics.
    """

    def rec(mode: str, voxel: float, n: int, parts: int, fps: float, sink: float, pz: float, vx: float) -> dict:
        return {"mode": mode, "voxel": voxel, "robots": n, "particles": parts, "graph": True, "build_s": 1.0,
                "capture_s": 0.1, "frames": 150, "frames_per_s": fps, "sinkage_m": sink, "max_sinkage_m": 3.0,
                "depth_m": 0.15, "pelvis_z_m": pz, "vx_mps": vx, "fallen": n}  # fmt: skip

    return {
        "window/v0.05/r1": rec("window", 0.05, 1, 17280, 107.7, 1.058, -0.388, -0.268),
        "multi/v0.05/r32": rec("multi", 0.05, 32, 552960, 30.8, 1.121, -0.426, -0.230),
        "naive/v0.05/r1": rec("naive", 0.05, 1, 251520, 54.4, 1.381, -0.639, -0.358),
        "multi/v0.04/r32": rec("multi", 0.04, 32, 1152000, 17.3, 0.897, -0.154, -0.146),
        "window/v0.04/r1": rec("window", 0.04, 1, 36000, 105.1, 0.818, -0.107, -0.407),
        "multi/v0.03/r32": {"mode": "multi", "voxel": 0.03, "robots": 32, "skipped": "predicted 131 s > 120 s left"},
    }


def test_convergence_ignores_skipped_and_failed_records() -> None:
    """The partial H100 results (a skipped multi case, no metrics) give a verdict over the measured voxels only."""
    bench = _load()
    res = _partial_h100_results()
    res["stand/v0.05/r4"] = {"mode": "stand", "voxel": 0.05, "robots": 4, "error": "RuntimeError('x')"}
    conv = bench._convergence(res, 0.15)
    assert set(conv) == {"multi"}
    rows = conv["multi"]["rows"]
    assert [r["voxel"] for r in rows] == [0.04, 0.05]
    assert rows[1]["sinkage_m_change"] == pytest.approx(1.121 - 0.897)
    assert rows[1]["floor_reached"] and rows[1]["accepted"] is False  # 3 m of sinkage on a 15 cm bed: no verdict


def test_resume_from_the_partial_h100_bench_runs_the_rest(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Rerun with the same --out: measured cases kept, the skipped one and the missing ones run, convergence done.

    ``_run_case`` (a GPU scene) is replaced by a recorder returning metrics that depend on the case, so this checks
    the resume bookkeeping only; ``test_tiny_cpu_run`` runs the real scene.
    """
    bench = _load()
    (tmp_path / "bench.json").write_text(json.dumps({"results": _partial_h100_results(), "warmup_s": 105.5}))
    ran: list[str] = []

    def fake_run(case: dict[str, Any], args: Any) -> dict[str, Any]:
        ran.append(bench._key(case) if args.frames > 3 or case["mode"] == "stand" else "warm-up")
        v = case["voxel"]
        return {**case, "particles": int(1.0 / v**3) * case["robots"], "graph": True, "capture_error": None,
                "build_s": 1.0, "capture_s": 0.1, "frames": args.frames, "frames_per_s": 2.0 / v, "episodes_per_min": 1.0,
                "batch_episode_s": 60.0, "sinkage_m": 0.02 + v, "max_sinkage_m": 0.05, "depth_m": 0.15,
                "pelvis_z_m": 0.7, "fallen": 0, "through_floor": 0, "soles_on_floor": 0, "soles_below_floor": 0,
                "vx_mps": 1.0 + case.get("iters", 50) / 1e4}  # fmt: skip

    monkeypatch.setattr(bench, "_run_case", fake_run)
    argv = ["bench", "--out", str(tmp_path), "--voxels", "0.05", "0.04", "0.03", "--robots", "32",
            "--max-minutes", "8"]  # fmt: skip
    monkeypatch.setattr(sys, "argv", argv)
    bench.main()
    assert ran == ["warm-up", "multi/v0.03/r32", "window/v0.03/r1", "multi/v0.05/r32/it250",
                   "stand/v0.05/r4", "stand/v0.04/r4", "stand/v0.03/r4"]  # fmt: skip
    doc = json.loads((tmp_path / "bench.json").read_text())
    assert doc["warmup_s"] == 105.5 and len(doc["warmups_s"]) == 1
    assert doc["results"]["multi/v0.05/r32"]["frames_per_s"] == 30.8  # the measured H100 record is kept
    assert set(doc["convergence"]) == {"multi", "stand", "iterations"}
    assert [r["voxel"] for r in doc["convergence"]["multi"]["rows"]] == [0.03, 0.04, 0.05]
    it = doc["convergence"]["iterations"]  # the 250-iteration rerun against the kept H100 record at 50
    assert it["vx_mps_at_250"] == pytest.approx(1.025) and it["vx_mps_change"] == pytest.approx(1.025 + 0.230)
    # a second rerun has nothing left: no warm-up, no case
    ran.clear()
    bench.main()
    assert ran == []


def test_robots_as_worlds_flag_reaches_the_scene_cfg() -> None:
    """--robots-as-worlds auto / yes / no -> G1MpmSceneCfg.robots_as_worlds None / True / False (GPU diagnostics)."""
    bench = _load()
    base = {"voxels": [0.05], "iters": 50, "window_length": 1.8, "window_width": 1.0, "device": "cpu"}
    case = {"mode": "window", "voxel": 0.05, "robots": 2}
    got = {f: bench._scene_cfg(case, bench.Namespace(**base, robots_as_worlds=f)).robots_as_worlds
           for f in ("auto", "yes", "no")}  # fmt: skip
    assert got == {"auto": None, "yes": True, "no": False}
