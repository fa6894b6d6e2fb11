# SPDX-License-Identifier: Apache-2.0
"""Sole calibration protocol, dataset contract and extension fit, on synthetic data from the float64 3D-RFT."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gmloco.contact import RftExtensionsCfg
from gmloco.contact.extensions_io import load_rft_extensions
from gmloco.eval.calibration.build import CalibrationBuildCfg, build_dataset, smoke_build_cfg
from gmloco.eval.calibration.dataset import ContractError, assign_split, check_contract, load_dataset, save_dataset
from gmloco.eval.calibration.fit import SandFitCfg, fit_extensions, write_default
from gmloco.eval.calibration.fit_cli import main as fit_main
from gmloco.eval.calibration.protocol import SoleProtocolCfg

TRUTH = RftExtensionsCfg(depth_exponent=1.3, lateral_scale=0.2, overburden=1.5)
"""Known terms of the synthetic sand."""
FAST = SoleProtocolCfg(time_scale=0.5)
"""Phases halved: enough frames for every term, a second per fit."""


def _build(tmp: Path, ext: RftExtensionsCfg, name: str, seed: int = 0) -> Path:
    """Write a reference-sand dataset with terms ``ext`` as ``tmp/name/dry_sand.npz``."""
    cfg = CalibrationBuildCfg(out_dir=str(tmp / name), sand="rft3d_reference", reference_extensions=ext,
                              protocol=FAST, split_seed=seed)  # fmt: skip
    return build_dataset(cfg)[0]


def test_protocol_reaches_single_stance_load(tmp_path: Path) -> None:
    """The press ends at the G1 weight (35 kg * 9.81 = 343.35 N) and the records are evenly sampled at frame_dt."""
    ds = load_dataset(_build(tmp_path, RftExtensionsCfg(), "plain"))
    press = ds.records["press"]
    loaded = press.force[press.phase == 0, 2]
    assert loaded[-1] < 343.35 <= press.force[press.phase == 1, 2][0] + 1e-9 or loaded.max() >= 343.35
    assert press.depth.max() > 0.005
    np.testing.assert_allclose(np.diff(press.time), ds.protocol.frame_dt)
    lift = ds.records["liftoff"]
    assert lift.force[-1, 2] == 0.0 and lift.depth[-1] < 0.0  # out of the sand: no force
    check_contract(ds, "g1", 100.0)


def test_split_is_deterministic_and_stored(tmp_path: Path) -> None:
    """The split depends only on the seed, holds out 40 % (>= 1 record) and is read back from the file."""
    names = ["a", "b", "c", "d", "e"]
    assert assign_split(names, 3) == assign_split(names, 3)
    assert sorted(assign_split(names, 3).values()).count("heldout") == 2
    ds = load_dataset(_build(tmp_path, RftExtensionsCfg(), "plain", seed=5))
    assert ds.split_seed == 5 and ds.split == assign_split(list(ds.records), 5)
    assert ds.extra is not None and ds.extra["meta"]["units"]["force"] == "N"


def test_fit_recovers_known_terms(tmp_path: Path) -> None:
    """Fitting synthetic data of known terms recovers them (1 %) and removes the held-out error."""
    ds = load_dataset(_build(tmp_path, TRUTH, "truth"))
    cfg = SandFitCfg(params=("depth_exponent", "lateral_scale", "overburden"), plastic_unloading="off", at_rest="none")
    result = fit_extensions(ds, cfg)
    fitted = result.extensions
    np.testing.assert_allclose(
        [fitted.depth_exponent, fitted.lateral_scale, fitted.overburden], [1.3, 0.2, 1.5], rtol=1e-2
    )
    assert result.accepted
    assert result.error_before["heldout"] > 1.0  # the published model misses the synthetic sand by > 1 N RMS
    assert result.error_after["heldout"] < 1e-2 * result.error_before["heldout"]
    out = write_default(result, tmp_path / "default.json", tmp_path / "truth" / "dry_sand.npz", cfg)
    assert out is not None and load_rft_extensions(out) == fitted


def test_fit_worse_on_heldout_is_refused(tmp_path: Path) -> None:
    """Fit records from one sand and held-out records from the published model: the fit is refused, nothing written."""
    truth = load_dataset(_build(tmp_path, RftExtensionsCfg(lateral_scale=0.2, overburden=1.5), "truth"))
    plain = load_dataset(_build(tmp_path, RftExtensionsCfg(), "plain"))
    mixed = replace(truth, records={n: (truth if truth.split[n] == "fit" else plain).records[n] for n in truth.records})
    path = save_dataset(mixed, tmp_path / "mixed" / "dry_sand.npz")
    args = ["--dataset", str(path), "--out", str(tmp_path / "fit.json"), "--write-default", str(tmp_path / "d.json"),
            "--params", "lateral_scale", "overburden", "--plastic-unloading", "off", "--at-rest", "none"]  # fmt: skip
    assert fit_main(args) == 1
    report = json.loads((tmp_path / "fit.json").read_text())
    assert not report["accepted"] and report["force_error_after"]["heldout"] > report["force_error_before"]["heldout"]
    assert not (tmp_path / "d.json").exists()


def test_fixed_term_is_held_and_the_rest_fitted(tmp_path: Path) -> None:
    """A term held at a value (--fixed) stays there.

    At the true value the free terms recover theirs (1 %); at a wrong one the fit costs more.
    """
    ds = load_dataset(_build(tmp_path, TRUTH, "truth"))
    cfg = SandFitCfg(params=("depth_exponent", "lateral_scale"), fixed=(("overburden", 1.5),),
                     plastic_unloading="off", at_rest="none")  # fmt: skip
    result = fit_extensions(ds, cfg)
    assert result.extensions.overburden == 1.5
    np.testing.assert_allclose(
        [result.extensions.depth_exponent, result.extensions.lateral_scale], [1.3, 0.2], rtol=1e-2
    )
    held_wrong = fit_extensions(ds, replace(cfg, fixed=(("overburden", 0.0),)))
    assert held_wrong.extensions.overburden == 0.0 and held_wrong.cost > 100.0 * max(result.cost, 1e-12)


@pytest.mark.parametrize(
    ("fixed", "message"),
    [("mud=1", "unknown"), ("overburden=50", "outside its fit bounds"), ("lateral_scale=1", "both fixed and fitted")],
)
def test_bad_fixed_term_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str], fixed: str, message: str) -> None:
    """A fixed term that is unknown, out of bounds or also fitted: exit 2 naming it, nothing written."""
    path = _build(tmp_path, RftExtensionsCfg(), "plain")
    args = ["--dataset", str(path), "--out", str(tmp_path / "fit.json"), "--params", "lateral_scale", "--fixed", fixed]
    assert fit_main(args) == 2
    assert message in capsys.readouterr().err and not (tmp_path / "fit.json").exists()
    with pytest.raises(SystemExit) as e:
        fit_main(["--dataset", str(path), "--out", str(tmp_path / "fit.json"), "--fixed", "added_mass"])
    assert e.value.code == 2


@pytest.mark.parametrize(
    ("change", "name"),
    [({"robot": "h1"}, "robot"), ({"units": {"force": "kN"}}, "units"), ({"rate": 50.0}, "rate")],
)
def test_contract_errors_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str], change: dict, name: str) -> None:
    """Wrong robot, units or rate: the fit exits 2 with a named contract error and writes nothing."""
    ds = load_dataset(_build(tmp_path, RftExtensionsCfg(), "plain"))
    rate = change.pop("rate", None)
    if "units" in change:
        ds.extra["meta"]["units"] = change["units"]  # pyright: ignore[reportOptionalSubscript]
        with pytest.raises(ContractError, match="units"):
            check_contract(ds, "g1", None)
    ds = replace(ds, robot=change.get("robot", ds.robot))
    if "units" not in change:
        path = save_dataset(ds, tmp_path / "bad" / "dry_sand.npz")
        args = ["--dataset", str(path), "--out", str(tmp_path / "fit.json")]
        args += ["--rate-hz", str(rate)] if rate else []
        assert fit_main(args) == 2
        assert f"contract error [{name}]" in capsys.readouterr().err
        assert not (tmp_path / "fit.json").exists()


def test_build_refuses_unknown_material(tmp_path: Path) -> None:
    """An unknown material is a ValueError naming the presets (the CLI turns it into exit 2)."""
    from gmloco.eval.calibration.__main__ import main

    assert main(["--material", "mud", "--out", str(tmp_path), "--sand", "rft3d_reference"]) == 2
    with pytest.raises(ValueError, match="unknown material"):
        build_dataset(CalibrationBuildCfg(material="mud", out_dir=str(tmp_path), sand="rft3d_reference"))


@pytest.mark.slow
def test_mpm_smoke_dataset(tmp_path: Path) -> None:
    """Tiny CPU MPM bed: the press experiment runs end to end and writes a readable dataset (not a physics check)."""
    cfg = replace(smoke_build_cfg("dry_sand", str(tmp_path)), experiments=("press",))
    path, timings = build_dataset(cfg)
    ds = load_dataset(path)
    rec = ds.records["press"]
    assert np.all(np.isfinite(rec.force)) and len(rec.time) > 3 and timings["press"]["particle_count"] > 0
