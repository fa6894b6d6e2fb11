# SPDX-License-Identifier: Apache-2.0
"""Box-study bookkeeping on a tiny case: records, resumption, summary."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from gmloco.eval.box_study import box_study_smoke_cfg, run, sample_media
from gmloco.eval.study_io import StudyRecords


def test_media_sampling_is_seeded_and_in_range(tmp_path: Path) -> None:
    """Same seed -> same media; rho_c = packing * bulk inside the configured ranges."""
    cfg = replace(box_study_smoke_cfg(str(tmp_path)), num_trials=50)
    a, b = sample_media(cfg), sample_media(cfg)
    np.testing.assert_array_equal(a["rho_c"], b["rho_c"])
    np.testing.assert_allclose(a["rho_c"], a["packing"] * a["bulk_density"])
    assert a["mu_int"].min() >= 0.2 and a["mu_int"].max() <= 0.9


def test_rom_study_records_and_resume(tmp_path: Path) -> None:
    """Two ROM models x 3 trials x 2 variants = 12 records; a second run adds none; summary per model."""
    cfg = replace(box_study_smoke_cfg(str(tmp_path)), num_trials=3, variants=("forward", "lateral"),
                  models=("rigid", "rft3d"))  # fmt: skip
    run(cfg)
    rows = StudyRecords(tmp_path).rows()
    assert len(rows) == 12
    assert {(r["variant"], r["trial"], r["model"]) for r in rows} == {
        (v, t, m) for v in ("forward", "lateral") for t in range(3) for m in ("rigid", "rft3d")
    }
    summary = run(cfg)
    assert len(StudyRecords(tmp_path).rows()) == 12 and summary["complete"]
    saved = json.loads((tmp_path / "summary.json").read_text())
    assert saved["variants"]["forward"]["scores"]["rft3d"]["matched_trials"] == 0  # no MPM reference yet
    # rigid: the box never penetrates the plane at z = 0 beyond MuJoCo's soft-contact impact penetration (mm)
    assert all(r["sinkage"] < 0.01 for r in rows if r["model"] == "rigid")


def test_mpm_smoke_trial_scored(tmp_path: Path) -> None:
    """One MPM trial (tiny bed, 0.2 s) plus Rigid and 3D-RFT: matched and scored, timings recorded."""
    cfg = replace(box_study_smoke_cfg(str(tmp_path)), models=("mpm", "rigid", "rft3d"))
    summary = run(cfg)
    fwd = summary["variants"]["forward"]
    assert fwd["mpm_trials_done"] == 1
    assert fwd["scores"]["rft3d"]["matched_trials"] == 1
    assert fwd["timing"]["mpm"]["particle_count"] > 0 and fwd["timing"]["mpm"]["frames_per_s_median"] > 0
    series = StudyRecords(tmp_path).series()
    mpm = next(s for s in series if s["model"] == "mpm")
    assert len(mpm["grf"]) == round(cfg.box.duration / cfg.mpm.frame_dt)
