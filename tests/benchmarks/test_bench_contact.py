# SPDX-License-Identifier: Apache-2.0
"""benchmarks/gpu/bench_contact.py on the CPU with tiny worlds: every record, one JSON, time box and resume."""

from __future__ import annotations

import json
from pathlib import Path
from types import ModuleType

from tests.contact.by_path import load_module


def bench_module() -> ModuleType:
    """Import benchmarks/gpu/bench_contact.py by path."""
    return load_module("bench_contact_script", "benchmarks/gpu/bench_contact.py")


def test_bench_writes_every_record_and_resumes(tmp_path: Path) -> None:
    """Time box 0 -> exit 3 and no record; rerun -> all 3D-RFT / baseline records on both paths, exit 0."""
    bench = bench_module()
    argv = ["--num-worlds", "3", "--reps", "2", "--device", "cpu", "--skip-sim", "--out", str(tmp_path)]
    assert bench.main([*argv, "--max-minutes", "0"]) == 3
    first = json.loads((tmp_path / "bench_contact.json").read_text())
    assert first["complete"] is False and first["models"] == {}
    assert bench.main(argv) == 0
    res = json.loads((tmp_path / "bench_contact.json").read_text())
    assert res["complete"] is True and res["num_worlds"] == 3 and res["device"] == "cpu"
    expected = {
        f"{m}/{n}pt{suffix}"
        for m in ("rft3d", "rft3d_viscous", "heuristic_rft", "cone_multi")
        for n in (25, 150)
        for suffix in ("", "/unfused")
    } | {"cone_single/1pt", "cone_single/1pt/unfused"}
    assert set(res["models"]) == expected
    for key, rec in res["models"].items():
        assert rec["compute_s"] > 0.0 and rec["update_state_s"] > 0.0, key
        if not key.endswith("/unfused"):  # fused vs unfused wrench: float32 round-off of the sum order
            assert rec["wrench_max_rel_diff_vs_unfused"] < 1e-5, key
    assert bench.main(argv) == 0  # resume: nothing left to time, records kept as they were
    again = json.loads((tmp_path / "bench_contact.json").read_text())
    assert again["models"] == res["models"]


def test_bench_refuses_a_foreign_setup(tmp_path: Path) -> None:
    """A rerun with another world count into the same folder is refused (exit 2) instead of mixing results."""
    bench = bench_module()
    argv = ["--reps", "1", "--device", "cpu", "--skip-sim", "--out", str(tmp_path), "--models", "cone_single"]
    assert bench.main(["--num-worlds", "2", *argv]) == 0
    assert bench.main(["--num-worlds", "5", *argv]) == 2
    assert bench.main(["--num-worlds", "2", *argv, "--paths", "fast"]) == 2


def test_bench_times_every_kernel_variant_side_by_side(tmp_path: Path) -> None:
    """--variants all: one record per fused 3D-RFT variant after the default one, each equal to it (diff 0).

    With --repeat 3 every call is timed three times and the median recorded.
    """
    bench = bench_module()
    argv = ["--num-worlds", "2", "--reps", "1", "--device", "cpu", "--skip-sim", "--out", str(tmp_path)]
    run = [*argv, "--models", "rft3d,cone_multi", "--paths", "fused", "--variants", "all", "--repeat", "3"]
    assert bench.main(run) == 0
    res = json.loads((tmp_path / "bench_contact.json").read_text())
    assert res["repeat"] == 3 and "gpu_clocks" not in res  # clocks only on CUDA
    for rec in res["models"].values():  # median of the three timed runs
        assert len(rec["compute_s_runs"]) == 3 and rec["compute_s"] == sorted(rec["compute_s_runs"])[1]
    variants = bench.all_variants()
    assert res["variants"] == list(variants) and variants[0] == "default" and "default-nopoints" in variants
    keys = [k for k in res["models"] if k.startswith("rft3d/150pt")]
    assert keys == ["rft3d/150pt", *(f"rft3d/150pt/{v}" for v in variants[1:])]  # side by side, in order
    for points in (25, 150):
        assert res["models"][f"rft3d/{points}pt"]["variant"] == "default"
        for v in variants[1:]:
            rec = res["models"][f"rft3d/{points}pt/{v}"]
            assert rec["variant"] == v and rec["compute_s"] > 0.0 and rec["max_rel_diff_vs_default"] == 0.0
            assert "step_s" in rec
    assert res["models"]["rft3d/150pt/default-nopoints"]["launches"]["step"] == ["rft3d_foot_step_kernel_nopoints"]
    assert res["models"]["rft3d/150pt/cap80"]["launches"]["step"] == ["rft3d_foot_step_kernel_maxreg80"]
    assert "variant" not in res["models"]["cone_multi/25pt"] and "cone_multi/25pt/cap80" not in res["models"]
    assert bench.main([*argv, "--models", "rft3d", "--variants", "fast"]) == 2
