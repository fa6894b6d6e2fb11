# SPDX-License-Identifier: Apache-2.0
"""Rheology-solver study bookkeeping on hand-made residual logs and probe rows (no simulation)."""

from __future__ import annotations

import math
import re
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
import warp as wp
from newton._src.solvers.implicit_mpm import solve_rheology as sr

from gmloco.eval.studies import solver_study
from gmloco.eval.studies.solver_study import (
    SolverStudyCfg,
    finite_residuals,
    parse_residual_log,
    summarize_probes,
    sweeps_to_reach,
)

_LOG = """\
cr terminated after 40 iterations with residual 0.5
gs iteration #25 \t res(l2)=0.001, res(linf)=0.01
some other line
gs iteration #50 \t res(l2)=2.5e-05, res(linf)=0.0003
"""


def test_residual_log_of_a_krylov_warm_started_solve() -> None:
    """Verbose sweeps become (iters, l2, linf) lists; the Krylov warm start goes to ``linear``."""
    curve = parse_residual_log(_LOG)
    assert curve["iters"] == [25, 50]
    assert curve["l2"] == [0.001, 2.5e-05]
    assert curve["linf"] == [0.01, 0.0003]
    assert curve["linear"] == [("cr", 40, "0.5")]


def test_nan_residuals_parse_to_nan() -> None:
    """A NaN norm (reserved-but-inactive nodes) is kept as a NaN report, not dropped."""
    curve = parse_residual_log("gs iteration #25 \t res(l2)=nan, res(linf)=nan\n")
    assert curve["iters"] == [25]
    assert math.isnan(curve["l2"][0]) and math.isnan(curve["linf"][0])


def test_an_empty_log_gives_empty_curves() -> None:
    """No verbose output: every list is empty."""
    assert parse_residual_log("") == {"iters": [], "l2": [], "linf": [], "linear": []}


def test_sweeps_to_reach_an_exactly_reported_residual() -> None:
    """A report equal to the target: its own sweep count."""
    assert sweeps_to_reach([25, 50, 75], [1e-2, 1e-3, 1e-4], 1e-3) == pytest.approx(50.0)


def test_sweeps_to_reach_interpolates_in_log_residual() -> None:
    """Between 1e-2 at 100 and 1e-4 at 200, 1e-3 lies half-way in log residual: 150; 2e-3 at 100 + 100 ln5/ln100."""
    assert sweeps_to_reach([100, 200], [1e-2, 1e-4], 1e-3) == pytest.approx(150.0)
    assert sweeps_to_reach([100, 200], [1e-2, 1e-4], 2e-3) == pytest.approx(100.0 + 100.0 * math.log(5) / math.log(100))


def test_sweeps_to_reach_a_residual_never_reached_is_inf() -> None:
    """The curve stays above the target: inf."""
    assert sweeps_to_reach([25, 50], [1e-2, 1e-3], 1e-4) == math.inf


def test_sweeps_to_reach_on_an_empty_curve_is_nan() -> None:
    """No reports: nan (unknown, not unreachable)."""
    assert math.isnan(sweeps_to_reach([], [], 1e-3))


def test_sweeps_to_reach_when_the_first_report_is_already_below() -> None:
    """Below the target at the first report: that report's sweep count (no extrapolation towards 0)."""
    assert sweeps_to_reach([25, 50], [1e-5, 1e-6], 1e-3) == 25.0


def _row(variant: str, iters: list[int], l2: list[float], error: str | None = None) -> dict[str, Any]:
    """A probe row as ``_probe`` writes it (linf = 10 l2, 1 s of eager wall time)."""
    return {"variant": variant, "iters": iters, "l2": l2, "linf": [10 * x for x in l2], "wall_s": 1.0, "error": error}


def test_summary_targets_the_reference_residual_and_counts_sweeps() -> None:
    """Target = median gs residual at 500 sweeps; per variant the median sweeps to it, medians at marks, errors."""
    cfg = SolverStudyCfg(variants=("gs", "jacobi"), probe_iterations=1000, reference_iterations=500)
    marks = [100, 250, 500, 1000]
    rows = [
        _row("gs", marks, [1e-1, 1e-2, 1e-3, 1e-4]),  # reaches 2e-3 at 250 + 250 ln5/ln10
        _row("gs", marks, [1e-1, 1e-2, 3e-3, 1e-4]),  # reaches it between 500 and 1000
        _row("gs", marks, [1e-1, 1e-2, 2e-3, 1e-4]),  # reaches it at 500 exactly
        _row("gs", [], [], error="RuntimeError('refused')"),
        _row("jacobi", marks, [1e-1, 3e-2, 1e-2, 1e-3]),  # reaches it at 500 + 500 ln5/ln10
        _row("jacobi", marks, [1e-1, 5e-2, 2e-2, 1e-2]),  # never: inf
        _row("jacobi", [50, 200, 450, 950], [1e-1, 2e-2, 1e-2, 2e-3]),  # at 950 exactly
    ]
    s = summarize_probes(rows, cfg)
    assert s["reference"] == "gs" and s["reference_iterations"] == 500
    assert s["target_l2"] == pytest.approx(2e-3)
    gs, jacobi = s["variants"]["gs"], s["variants"]["jacobi"]
    assert gs["probes"] == 4 and gs["errors"] == ["RuntimeError('refused')"]
    assert jacobi["probes"] == 3 and jacobi["errors"] == []
    assert gs["sweeps_to_target_median"] == pytest.approx(500.0)
    assert jacobi["sweeps_to_target_median"] == pytest.approx(950.0)
    assert [gs[f"l2_at_{n}"] for n in marks] == pytest.approx([1e-1, 1e-2, 2e-3, 1e-4])
    # the off-mark probe counts with its last report at or before each mark
    assert [jacobi[f"l2_at_{n}"] for n in marks] == pytest.approx([1e-1, 3e-2, 1e-2, 2e-3])
    assert "l2_at_2000" not in gs  # beyond the probe cap
    assert gs["eager_ms_per_sweep_median"] == pytest.approx(1.0)


def test_summary_without_reference_curves_has_no_target() -> None:
    """Every reference probe failed: the target and the sweeps to it are nan, the errors are kept."""
    cfg = SolverStudyCfg(variants=("gs", "jacobi"), probe_iterations=1000, reference_iterations=500)
    s = summarize_probes([_row("gs", [], [], error="boom"), _row("jacobi", [100], [1e-2])], cfg)
    assert math.isnan(s["target_l2"])
    assert s["variants"]["gs"]["errors"] == ["boom"] and math.isnan(s["variants"]["gs"]["l2_at_100"])
    assert math.isnan(s["variants"]["jacobi"]["sweeps_to_target_median"])


def test_finite_residuals_patches_newton_and_restores_it() -> None:
    """Inside, the rheology solver's eval_residual is replaced; afterwards (also after an error) it is back."""
    before = sr._RheologySolver.eval_residual
    with finite_residuals([]) as counts:
        assert sr._RheologySolver.eval_residual is not before
        assert counts == []
    assert sr._RheologySolver.eval_residual is before
    with pytest.raises(ZeroDivisionError), finite_residuals([]):
        assert sr._RheologySolver.eval_residual is not before
        _ = 1 / 0
    assert sr._RheologySolver.eval_residual is before


def test_finite_residuals_norm_skips_nan_entries(monkeypatch: pytest.MonkeyPatch) -> None:
    """The patched norm is [[sum], [max]] over the finite entries; (finite, all) counts are recorded."""
    calls: list[Any] = []
    monkeypatch.setattr(sr._RheologySolver, "eval_residual", lambda self: calls.append(self))
    nan = float("nan")
    fake = SimpleNamespace(
        strain_residual=wp.array([1.0, nan, 2.0, 0.5, nan], dtype=wp.float32, device="cpu"), device="cpu"
    )
    counts: list[tuple[int, int]] = []
    with finite_residuals(counts):
        patched: Any = sr._RheologySolver.eval_residual
        out = patched(fake)
    assert calls == [fake]  # Newton's own evaluation still runs first
    np.testing.assert_allclose(out.numpy(), [[3.5], [2.0]])
    assert counts == [(3, 5)]


def test_a_probe_cap_below_newtons_report_interval_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """--probe-iterations 10 would give no residual report: a usage error before any scene is built."""

    def no_study(*_: object) -> None:
        raise AssertionError("run_study must not be reached")

    monkeypatch.setattr(solver_study, "run_study", no_study)
    with pytest.raises(SystemExit):
        solver_study.main(["--policy", "p.onnx", "--out", str(tmp_path), "--probe-iterations", "10"])
    assert "--probe-iterations" in capsys.readouterr().err


OPTIONS = {"-h", "--help", "--policy", "--out", "--variants", "--robots", "--speed", "--terrain", "--voxel", "--warm-s",
           "--probe-iterations", "--cycles", "--cell-capacity-factor", "--device"}  # fmt: skip
"""The option strings of the study's command line as the recorded commands know it (hand-written, 12 flags)."""
RECORDED = ["--variants", "gs", "jacobi", "jacobi,gs", "gs-batched", "--robots", "8", "--warm-s", "1.0",
            "--probe-iterations", "2000", "--cycles", "3"]  # fmt: skip
"""The study's arguments as ``results/`` records them (besides ``--policy`` and ``--out``)."""


def _stop_before_the_study(monkeypatch: pytest.MonkeyPatch) -> list[tuple[Any, SolverStudyCfg]]:
    """Replace the study by a recorder of its configs (no scene is built)."""
    calls: list[tuple[Any, SolverStudyCfg]] = []

    def record(eval_cfg: Any, cfg: SolverStudyCfg, _out: Path) -> dict[str, Any]:
        calls.append((eval_cfg, cfg))
        return {"variants": {}}

    monkeypatch.setattr(solver_study, "run_study", record)
    return calls


def test_help_lists_the_recorded_options(capsys: pytest.CaptureFixture[str]) -> None:
    """The generated flags and the command line's own give exactly the option strings the commands were written with."""
    with pytest.raises(SystemExit) as stop:
        solver_study.main(["--help"])
    assert stop.value.code == 0
    assert set(re.findall(r"(?<![\w-])-{1,2}[a-z][\w-]*", capsys.readouterr().out.split("options:")[1])) == OPTIONS


def test_the_recorded_command_fills_the_study_and_evaluation_configs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The recorded flags set the study's fields; robots, speed, terrain and voxel reach the evaluation setting."""
    calls = _stop_before_the_study(monkeypatch)
    solver_study.main(["--policy", "p.onnx", "--out", str(tmp_path), *RECORDED, "--speed", "1.5", "--voxel", "0.04"])
    (eval_cfg, cfg), = calls  # fmt: skip
    assert cfg == SolverStudyCfg(variants=("gs", "jacobi", "jacobi,gs", "gs-batched"), speed=1.5, voxel_size=0.04)
    assert (eval_cfg.num_episodes, eval_cfg.robots_per_batch, eval_cfg.speeds, eval_cfg.terrains) == (
        8, 8, (1.5,), ("dry_sand",))  # fmt: skip
    assert eval_cfg.solver.voxel_size == 0.04 and eval_cfg.policy_path == "p.onnx" and not eval_cfg.record_mcap


@pytest.mark.parametrize(
    ("flag", "value", "message"),
    [
        ("--robots", "0", "--robots 0 must be >= 1"),
        ("--cycles", "0", "--cycles 0 must be >= 1"),
        ("--robots", "eight", "argument --robots: invalid int value: 'eight'"),
        ("--voxel", "0", "--voxel 0.0 must be > 0"),
        ("--cell-capacity-factor", "0.5", "--cell-capacity-factor 0.5 must be >= 1 or 0"),
    ],
)
def test_malformed_or_out_of_range_flags_exit_2(
    flag: str, value: str, message: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    """A malformed or out-of-range value is a usage error (exit code 2) naming the flag, before any scene is built."""
    calls = _stop_before_the_study(monkeypatch)
    with pytest.raises(SystemExit) as stop:
        solver_study.main(["--policy", "p.onnx", "--out", str(tmp_path), flag, value])
    assert stop.value.code == 2 and not calls
    assert message in capsys.readouterr().err
