# SPDX-License-Identifier: Apache-2.0
"""The shear study: twist torque, support after a slide, re-press depth, and its command line, on float64 3D-RFT data."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gmloco.contact import RftExtensionsCfg
from gmloco.contact.extensions_io import save_rft_extensions
from gmloco.eval.calibration.build import CalibrationBuildCfg, build_dataset
from gmloco.eval.calibration.dataset import load_dataset
from gmloco.eval.calibration.protocol import PROBE_EXPERIMENTS, SoleProtocolCfg
from gmloco.eval.calibration.shear import drag_response, main, resupport_response, twist_response

FAST = SoleProtocolCfg(time_scale=0.5)
TRUTH = RftExtensionsCfg(lateral_scale=0.3)


def _dataset(tmp: Path, experiments: tuple[str, ...] = ("press", "drag", "twist")) -> Path:
    """Reference-sand dataset of dry sand with the lateral scale 0.3."""
    cfg = CalibrationBuildCfg(out_dir=str(tmp), sand="rft3d_reference", protocol=FAST, reference_extensions=TRUTH,
                              experiments=experiments)  # fmt: skip
    return build_dataset(cfg)[0]


def test_response_opposes_each_turn_and_reads_the_load(tmp_path: Path) -> None:
    """The resisting torque changes sign with the turn (+, -, +); the hold carries the single-stance load."""
    rec = load_dataset(_dataset(tmp_path)).records["twist"]
    r = twist_response(rec.force, rec.torque[:, 2], rec.phase)
    assert r["load_N"] == pytest.approx(FAST.weight, rel=0.1)
    signs = [np.sign(r[f"turn_{i}"]["torque_mean_Nm"]) for i in (1, 2, 3)]
    assert signs == [-1.0, 1.0, -1.0]
    assert all(abs(r[f"turn_{i}"]["torque_peak_Nm"]) >= abs(r[f"turn_{i}"]["torque_mean_Nm"]) for i in (1, 2, 3))
    with pytest.raises(ValueError, match="not a twist record"):
        twist_response(rec.force, rec.torque[:, 2], np.zeros_like(rec.phase))


def test_cli_replays_the_true_terms_exactly(tmp_path: Path) -> None:
    """A model with the data's own terms reproduces the data's twist at datum ~0; the published model resists 1/0.3 x."""
    path = _dataset(tmp_path / "ds")
    terms = save_rft_extensions(TRUTH, tmp_path / "truth.json", {"made_by": "test"})
    assert main(["--dataset", str(path), "--model", f"truth={terms}", "--out", str(tmp_path / "out")]) == 0
    row = json.loads((tmp_path / "out" / "summary.json").read_text())["materials"]["dry_sand"]
    data, truth, published = row["rft3d_reference"], row["truth"], row["published 3D-RFT"]
    assert abs(truth["datum_m"]) < 1e-3
    for i in (1, 2, 3):
        t = f"turn_{i}"
        assert truth[t]["torque_mean_Nm"] == pytest.approx(data[t]["torque_mean_Nm"], rel=0.05)
        assert abs(published[t]["torque_mean_Nm"]) > 2.0 * abs(data[t]["torque_mean_Nm"])
    assert (tmp_path / "out" / "fig_twist.png").stat().st_size > 10_000
    drag = row["drag"]
    assert drag["truth"]["support_kept"] == pytest.approx(drag["rft3d_reference"]["support_kept"], rel=0.05)
    assert drag["rft3d_reference"]["load_N"] == pytest.approx(0.5 * FAST.weight, rel=0.2)  # pressed to half the load
    assert (tmp_path / "out" / "fig_drag.png").stat().st_size > 10_000


def test_drag_response_reads_the_support_left_after_the_slide() -> None:
    """Synthetic drag: 100 N before, a slide at 10 N sideways, 25 N after: a quarter of the support kept."""
    phase = np.repeat([0, 1, 2, 3], 5)
    force = np.zeros((20, 3))
    force[phase == 1, 2], force[phase == 2, 0], force[phase == 2, 2], force[phase == 3, 2] = 100.0, 10.0, 40.0, 25.0
    r = drag_response(force, phase)
    assert (r["load_N"], r["drag_force_N"], r["support_after_N"], r["support_kept"]) == (100.0, 10.0, 25.0, 0.25)
    with pytest.raises(ValueError, match="not a drag record"):
        drag_response(force, np.zeros(20, dtype=int))


def test_bad_input_exits_2(tmp_path: Path) -> None:
    """No dataset, one without a twist (or probe) record, a model without LABEL=, or a missing terms file: exit 2."""
    press_only = _dataset(tmp_path / "p", ("press",))
    assert main(["--dataset", str(press_only), "--out", str(tmp_path / "o")]) == 2
    assert main(["--probes", str(press_only), "--out", str(tmp_path / "o")]) == 2
    assert main(["--out", str(tmp_path / "o")]) == 2
    assert main(["--predict", "mud", "--out", str(tmp_path / "o")]) == 2
    twist = _dataset(tmp_path / "t")
    assert main(["--dataset", str(twist), "--model", "no_label", "--out", str(tmp_path / "o")]) == 2
    assert main(["--dataset", str(twist), "--model", f"x={tmp_path / 'none.json'}", "--out", str(tmp_path / "o")]) == 2
    assert not (tmp_path / "o" / "summary.json").exists()


def test_probe_on_the_reference_needs_no_extra_depth(tmp_path: Path) -> None:
    """3D-RFT gives a slid or turned sole its support back at rest: re-pressing it needs < 1 mm; the CLI agrees."""
    cfg = CalibrationBuildCfg(out_dir=str(tmp_path / "probes"), sand="rft3d_reference", protocol=FAST,
                              reference_extensions=TRUTH, experiments=PROBE_EXPERIMENTS)  # fmt: skip
    path = build_dataset(cfg)[0]
    ds = load_dataset(path)
    for name in PROBE_EXPERIMENTS:
        rec = ds.records[name]
        r = resupport_response(rec.depth, rec.force, rec.phase)
        assert r["reloaded"] and abs(r["extra_depth_m"]) < 1e-3 and r["load_N"] == pytest.approx(FAST.weight, rel=0.1)
    terms = save_rft_extensions(TRUTH, tmp_path / "truth.json", {"made_by": "test"})
    assert main(["--probes", str(path), "--model", f"truth={terms}", "--out", str(tmp_path / "out")]) == 0
    rows = json.loads((tmp_path / "out" / "summary.json").read_text())["probes"]["dry_sand"]
    for name in PROBE_EXPERIMENTS:
        assert rows[name]["truth"]["extra_depth_m"] == pytest.approx(
            rows[name]["rft3d_reference"]["extra_depth_m"], abs=1e-9
        )
    assert (tmp_path / "out" / "fig_resupport.png").stat().st_size > 5_000


def test_prediction_needs_no_record_and_sees_the_loosening(tmp_path: Path) -> None:
    """--predict runs each model's probes on a material alone; a loosening model needs extra depth, 3D-RFT none."""
    loose = save_rft_extensions(RftExtensionsCfg(loosening_depth=0.01, loosening_length=0.02), tmp_path / "l.json",
                                {"made_by": "test"})  # fmt: skip
    assert main(["--predict", "dry_sand", "--model", f"loose={loose}", "--out", str(tmp_path / "out")]) == 0
    pred = json.loads((tmp_path / "out" / "summary.json").read_text())["probe_predictions"]["dry_sand"]
    slide = pred["slide_repress"]
    assert abs(slide["published 3D-RFT"]["extra_depth_m"]) < 1e-3
    assert slide["loose"]["extra_depth_m"] > 0.003 and slide["loose"]["reloaded"] and slide["loose"]["loaded"]


def test_resupport_response_reads_the_extra_depth() -> None:
    """Synthetic probe: loaded at 2 cm, support 30 N after the slide, loaded again at 5 cm: 3 cm extra."""
    phase = np.repeat([0, 1, 2, 3, 4, 5], 4)
    depth = np.select([phase <= 3, phase == 4], [0.02, 0.035], 0.05)
    force = np.zeros((24, 3))
    force[:, 2] = np.select([phase == 3, phase == 2], [30.0, 100.0], 343.0)
    r = resupport_response(depth, force, phase)
    assert r["extra_depth_m"] == pytest.approx(0.03) and r["support_after_move_N"] == 30.0 and r["reloaded"]
    assert "loaded" not in r and resupport_response(depth, force, phase, 343.0)["loaded"]
    assert not resupport_response(depth, force, phase, 1000.0)["loaded"]  # the sand never carried that load
    with pytest.raises(ValueError, match="not a probe record"):
        resupport_response(depth, force, np.zeros(24, dtype=int))
