# SPDX-License-Identifier: Apache-2.0
"""Per-term verdicts on synthetic data from the float64 3D-RFT with one known extension term switched on."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gmloco.contact import RftExtensionsCfg
from gmloco.eval.calibration.build import CalibrationBuildCfg, build_dataset
from gmloco.eval.calibration.dataset import assign_split, load_dataset
from gmloco.eval.calibration.fit import SandFitCfg
from gmloco.eval.calibration.protocol import SoleProtocolCfg
from gmloco.eval.calibration.verdicts import TermVerdictCfg, _verdict, term_verdicts
from gmloco.eval.calibration.verdicts import main as verdicts_main

TRUTH = RftExtensionsCfg(lateral_scale=0.2)
"""The synthetic sand: 3D-RFT with its horizontal force at 1/5 (the box study's direction), nothing else."""
EXPERIMENTS = ("press", "drag", "tilt", "liftoff")
"""Enough to identify a lateral scale (drag, tilt) and an overburden (liftoff)."""
FIT = SandFitCfg(at_rest="none")
"""The reference sand's own at-rest mode, so the true terms reproduce it exactly."""


def _seed_holding_out(name: str) -> int:
    """Return the first split seed that holds ``name`` out (the split is drawn before any fit)."""
    return next(s for s in range(100) if assign_split(list(EXPERIMENTS), s)[name] == "heldout")


def _build(tmp: Path, ext: RftExtensionsCfg = TRUTH) -> Path:
    """Write a small reference-sand dataset with terms ``ext`` whose held-out part includes the drag."""
    cfg = CalibrationBuildCfg(out_dir=str(tmp), sand="rft3d_reference", reference_extensions=ext,
                              protocol=SoleProtocolCfg(time_scale=0.3), experiments=EXPERIMENTS,
                              split_seed=_seed_holding_out("drag"))  # fmt: skip
    return build_dataset(cfg)[0]


def test_known_term_kept_absent_term_rejected(tmp_path: Path) -> None:
    """Lateral scale (switched on) is kept and fitted to its value; overburden (off in the data) is rejected."""
    ds = load_dataset(_build(tmp_path))
    out = term_verdicts(ds, TermVerdictCfg(terms=("lateral_scale", "overburden"), fit=FIT))
    lateral, overburden = out["terms"]["lateral_scale"], out["terms"]["overburden"]
    assert out["kept"] == ["lateral_scale"]
    np.testing.assert_allclose(lateral["values"]["lateral_scale"], 0.2, rtol=1e-3)
    assert lateral["heldout_with_N"] < 1e-2 * lateral["heldout_without_N"]  # exact model: ~0 N held out
    assert overburden["verdict"] == "rejected" and "changes < 2 % or < 0.1 N" in overburden["reason"]
    assert abs(overburden["heldout_with_N"] - overburden["heldout_without_N"]) < 0.1  # below the 0.1 N floor
    assert out["fit_cli_args"] == ["--params", "lateral_scale", "--plastic-unloading", "off"]


def test_verdict_reasons() -> None:
    """The reasons of the rules: < 2 % held out, worse with it, fit split only, at a bound, kept."""
    cfg = TermVerdictCfg()
    base = {"heldout_with_N": 10.0, "heldout_without_N": 10.1, "fit_with_N": 5.0, "fit_without_N": 5.05,
            "heldout_change": 0.01, "fit_change": 0.01, "alone_change": 0.0, "at_bound": []}  # fmt: skip
    assert _verdict(base, cfg)[1].startswith("held-out force error changes < 2 %")
    assert "improves fit split only" in _verdict({**base, "fit_change": 0.3, "fit_with_N": 3.5}, cfg)[1]
    worse = {**base, "heldout_with_N": 12.0, "heldout_change": -0.2}
    assert _verdict(worse, cfg)[1].startswith("held-out force error is higher with it")
    tiny = {**base, "heldout_with_N": 1e-5, "heldout_without_N": 1e-4, "heldout_change": 0.9}  # noise: < 0.1 N
    assert _verdict(tiny, cfg)[0] == "rejected"
    bound = {**base, "heldout_without_N": 20.0, "heldout_change": 0.5, "at_bound": ["lateral_scale = 2 (bounds 0..2)"]}
    assert _verdict(bound, cfg) == ("rejected", "fitted value at its bound: lateral_scale = 2 (bounds 0..2)")
    # without 20 N, with 10 N: change (20 - 10) / 20 = 0.5 >= 0.02 and 10 N >= 0.1 N
    kept = _verdict({**base, "heldout_without_N": 20.0, "heldout_change": 0.5}, cfg)
    assert kept == ("kept", "dropping it raises the held-out force error from 10 N to 20 N")


def test_cli_writes_json_and_bad_input_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The command writes the verdicts; a missing dataset or a bad threshold exits 2 and writes nothing."""
    path = _build(tmp_path / "ds")
    out = tmp_path / "verdicts_dry_sand.json"
    args = ["--dataset", str(path), "--out", str(out), "--terms", "lateral_scale", "--at-rest", "none"]
    assert verdicts_main(args) == 0
    body = json.loads(out.read_text())
    assert body["material"] == "dry_sand" and body["terms"]["lateral_scale"]["verdict"] == "kept"
    bad = tmp_path / "bad.json"
    assert verdicts_main(["--dataset", str(tmp_path / "none.npz"), "--out", str(bad)]) == 2
    assert verdicts_main(["--dataset", str(path), "--out", str(bad), "--min-change", "1.5"]) == 2
    assert "error:" in capsys.readouterr().err and not bad.exists()


@pytest.mark.slow
def test_every_term_judged(tmp_path: Path) -> None:
    """All five terms on data with a depth law and a lateral scale: those two kept, the other three rejected."""
    ds = load_dataset(_build(tmp_path, RftExtensionsCfg(depth_exponent=1.3, lateral_scale=0.2)))
    out = term_verdicts(ds, TermVerdictCfg(fit=FIT))
    assert out["kept"] == ["depth_law", "lateral_scale"]
    assert {t: r["verdict"] for t, r in out["terms"].items()} == {
        "depth_law": "kept", "lateral_scale": "kept", "plastic_unloading": "rejected", "overburden": "rejected",
        "added_mass": "rejected"}  # fmt: skip


def test_fitted_datum_recovers_a_raised_surface(tmp_path: Path) -> None:
    """A sand whose surface sits 6 mm above the nominal top: the fit finds the datum, the published model is aligned."""
    from dataclasses import replace

    from gmloco.eval.calibration.fit import fit_extensions, split_error

    ds = load_dataset(_build(tmp_path))
    shifted = replace(
        ds, records={n: replace(r, pos=r.pos + np.array([0.0, 0.0, 0.006])) for n, r in ds.records.items()}
    )
    res = fit_extensions(shifted, replace(FIT, params=("lateral_scale",), plastic_unloading="off"))
    np.testing.assert_allclose(res.datum, 0.006, atol=2e-4)
    assert res.error_after["heldout"] < 0.05 * res.error_before["heldout"]
    assert res.error_before_aligned is not None and res.error_before_aligned["heldout"] < res.error_before["heldout"]
    nominal, _ = split_error(shifted, res.extensions, FIT)  # the same terms at the nominal datum fit worse
    assert nominal["heldout"] > res.error_after["heldout"]
