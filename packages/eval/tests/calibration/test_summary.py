# SPDX-License-Identifier: Apache-2.0
"""Calibration summary from a synthetic dataset (float64 3D-RFT with a known depth law) and its fit."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gmloco.contact import RftExtensionsCfg
from gmloco.eval.calibration.build import CalibrationBuildCfg, build_dataset
from gmloco.eval.calibration.dataset import load_dataset
from gmloco.eval.calibration.fit import SandFitCfg
from gmloco.eval.calibration.fit_cli import main as fit_main
from gmloco.eval.calibration.protocol import SoleProtocolCfg
from gmloco.eval.calibration.summary import NOT_FROM_SOLE_DATA, SUMMARY_KEYS, SummaryCfg, stance_depth
from gmloco.eval.calibration.summary import main as summary_main
from gmloco.eval.calibration.verdicts import main as verdicts_main

TRUTH = RftExtensionsCfg(depth_exponent=1.3)
"""The synthetic sand: 3D-RFT with a stiffer-than-linear depth law, nothing else."""
EXPERIMENTS = ("press", "drag", "liftoff")
"""Small and enough for a depth law."""
FIT_ARGS = ["--params", "depth_exponent", "--plastic-unloading", "off", "--at-rest", "none"]
"""The fit of the true term in the reference sand's own at-rest mode."""


def _build(tmp: Path, ext: RftExtensionsCfg = TRUTH) -> Path:
    """Write a small reference-sand dataset with terms ``ext``."""
    cfg = CalibrationBuildCfg(out_dir=str(tmp), sand="rft3d_reference", reference_extensions=ext,
                              protocol=SoleProtocolCfg(time_scale=0.3), experiments=EXPERIMENTS)  # fmt: skip
    return build_dataset(cfg)[0]


@pytest.fixture
def fitted(tmp_path: Path) -> tuple[Path, Path]:
    """Return (dataset, fit report) of the known depth law."""
    ds = _build(tmp_path / "dataset")
    report = tmp_path / "out" / "fit_dry_sand.json"
    assert fit_main(["--dataset", str(ds), "--out", str(report), *FIT_ARGS]) == 0
    return ds, report


def test_summary_keys_nulls_and_figures(fitted: tuple[Path, Path], tmp_path: Path) -> None:
    """Every issue key is present; the three it cannot compute are null with a reason; the fit passes its checks."""
    ds, report = fitted
    out = tmp_path / "out" / "summary.json"
    verdicts = tmp_path / "out" / "verdicts_dry_sand.json"
    args = ["--dataset", str(ds), "--out", str(verdicts), "--terms", "depth_law", "--at-rest", "none"]
    assert verdicts_main(args) == 0
    assert (
        summary_main(["--fits", str(report), "--datasets", str(ds), "--verdicts", str(verdicts), "--out", str(out)])
        == 0
    )
    body = json.loads(out.read_text())
    assert set(SUMMARY_KEYS) <= set(body)
    for key in NOT_FROM_SOLE_DATA:
        assert body[key] is None and body["missing"][key]
    before, after = body["force_error_before"]["dry_sand"], body["force_error_after"]["dry_sand"]
    assert after["N"] < 1e-2 * before["N"] and 0.0 < before["relative"] < 1.0
    depth = body["stance_depth_error_pct"]["dry_sand"]
    np.testing.assert_allclose(depth["load_N"], 35.0 * 9.81)
    assert abs(depth["after"]) < 0.5 < abs(depth["before"])  # the fitted depth law gives the sand's depth
    assert body["pass"]["force_error_halved"] == {"dry_sand": True}
    assert body["pass"]["stance_depth_within_20_pct"] == {"dry_sand": True} and body["pass"]["all"] is None
    assert body["sources"] == {"dry_sand": "rft3d_reference"} and body["fit_accepted"] == {"dry_sand": True}
    assert body["term_verdicts"]["dry_sand"]["depth_law"]["verdict"] == "kept"
    for fig in ("force_depth_dry_sand.png", "term_errors_dry_sand.png"):
        assert (out.parent / fig).stat().st_size > 1000 and str(out.parent / fig) in body["figures"]


def test_stance_depth_of_the_published_model_is_exact(tmp_path: Path) -> None:
    """On data from the published 3D-RFT both models press to the sand's own depth: 0 % error before and after."""
    ds = load_dataset(_build(tmp_path, RftExtensionsCfg()))
    depth, reason = stance_depth(ds, RftExtensionsCfg(), SandFitCfg(at_rest="none"), SummaryCfg())
    assert reason is None and depth is not None
    np.testing.assert_allclose([depth["before"], depth["after"]], 0.0, atol=1e-9)
    # 3D-RFT is linear in depth for a flat sole: half the load sinks it about half as deep (the box's sides add
    # a little), so the depth at half the weight lies between 0.4 and 0.6 of the depth at the weight
    half, _ = stance_depth(ds, RftExtensionsCfg(), SandFitCfg(at_rest="none"), SummaryCfg(stance_load_fraction=0.5))
    assert half is not None and 0.4 < half["sand_depth_m"] / depth["sand_depth_m"] < 0.6


def test_bad_input_exits_2(fitted: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A missing report, a report that is not a fit, a dataset not given or changed, a bad load share: exit 2."""
    _, report = fitted
    out = tmp_path / "summary.json"
    other = _build(tmp_path / "other", RftExtensionsCfg())
    not_a_fit = tmp_path / "x.json"
    not_a_fit.write_text(json.dumps({"accepted": True}))
    stale = tmp_path / "stale.json"
    stale.write_text(json.dumps({**json.loads(report.read_text()), "dataset_sha256": "0" * 64}))
    for args in (["--fits", str(tmp_path / "none.json")], ["--fits", str(not_a_fit)],
                 ["--fits", str(report), "--datasets", str(other)], ["--fits", str(stale)],
                 ["--fits", str(report), "--stance-load-fraction", "1.5"]):  # fmt: skip
        assert summary_main([*args, "--out", str(out), "--no-figures"]) == 2
        assert "error:" in capsys.readouterr().err and not out.exists()


def _predicted_file(tmp: Path, models: tuple[str, ...], max_points: float = 15.0) -> Path:
    """Write a prediction of one policy on dry sand at 1 m/s: MPM 76 %, every model 80 % (within 15 points)."""
    from gmloco.eval.calibration.predict import main as predict_main

    gate_paths = []
    for model in models:
        gate = tmp / f"gate_{model}.json"
        gate.write_text(json.dumps({"policy": "artifacts/gm_loco_student_td", "success_pct": {"dry_sand": {"1": 80.0}},
                                    "success_course_pct": {"dry_sand": {"1": 80.0}},
                                    "setup": {"contact_model": model}}))  # fmt: skip
        gate_paths.append(str(gate))
    mpm = tmp / "mpm.json"
    row = {"policy": "gm_loco_student_td", "terrain": "dry_sand", "scenario": "straight", "v=1 m/s": 76.0}
    mpm.write_text(json.dumps({"speed_rows": [row]}))
    out = tmp / "predicted.json"
    assert predict_main(["--gate", *gate_paths, "--mpm", str(mpm), "--out", str(out), "--no-figures"]) == 0
    if max_points != 15.0:
        out.write_text(json.dumps({**json.loads(out.read_text()), "max_points": max_points}))
    return out


def test_predicted_success_fills_its_key_and_check(
    fitted: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--predicted fills predicted_vs_mpm_success and judges the calibrated model; a file judged otherwise exits 2."""
    _, report = fitted
    out = tmp_path / "summary.json"
    predicted = _predicted_file(tmp_path, ("rft3d", "rft3d_calibrated"))
    assert summary_main(["--fits", str(report), "--predicted", str(predicted), "--out", str(out), "--no-figures"]) == 0
    body = json.loads(out.read_text())
    cell = body["predicted_vs_mpm_success"]["gm_loco_student_td"]["dry_sand"]["1"]
    assert cell["mpm_success_pct"] == 76.0 and cell["difference_points"] == {"rft3d": 4.0, "rft3d_calibrated": 4.0}
    assert "predicted_vs_mpm_success" not in body["missing"] and body["inputs"]["predicted"] == str(predicted)
    assert body["pass"]["predicted_success_within_15_points"] == {"gm_loco_student_td": True}
    (tmp_path / "p").mkdir()
    published_only = _predicted_file(tmp_path / "p", ("rft3d",))
    assert (
        summary_main(["--fits", str(report), "--predicted", str(published_only), "--out", str(out), "--no-figures"])
        == 0
    )
    body = json.loads(out.read_text())
    assert body["pass"]["predicted_success_within_15_points"] == {"gm_loco_student_td": None}
    assert "rft3d_calibrated" in body["missing"]["predicted_vs_mpm_success.gm_loco_student_td"]
    out.unlink()
    (tmp_path / "q").mkdir()
    other = _predicted_file(tmp_path / "q", ("rft3d_calibrated",), max_points=10.0)
    assert summary_main(["--fits", str(report), "--predicted", str(other), "--out", str(out), "--no-figures"]) == 2
    assert "within 10.0 points, not 15.0" in capsys.readouterr().err and not out.exists()
