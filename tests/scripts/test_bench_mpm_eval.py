# SPDX-License-Identifier: Apache-2.0
"""scripts/gpu/bench_mpm_eval.py: case order, the convergence verdicts on hand-made results, a tiny CPU run."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from types import ModuleType

import pytest

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts" / "gpu"
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
    assert set(doc["convergence"]) == {"multi", "stand", "iterations"}
