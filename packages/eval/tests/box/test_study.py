# SPDX-License-Identifier: Apache-2.0
"""Box-study bookkeeping on a tiny case: records, resumption, summary."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gmloco.eval.box.study import box_study_smoke_cfg, run, sample_media
from gmloco.eval.studies.study_io import StudyRecords


def test_media_sampling_is_seeded_and_in_range(tmp_path: Path) -> None:
    """Same seed -> same media; rho_c = packing * bulk inside the configured ranges."""
    cfg = replace(box_study_smoke_cfg(str(tmp_path)), num_trials=50)
    a, b = sample_media(cfg), sample_media(cfg)
    np.testing.assert_array_equal(a["rho_c"], b["rho_c"])
    np.testing.assert_allclose(a["rho_c"], a["packing"] * a["bulk_density"])
    assert a["mu_int"].min() >= 0.2 and a["mu_int"].max() <= 0.9
    # the first trials do not depend on how many there are (convergence / size checks reuse them)
    few = sample_media(replace(cfg, num_trials=5))
    np.testing.assert_array_equal(few["rho_c"], a["rho_c"][:5])


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


def test_resume_under_other_settings_is_refused(tmp_path: Path) -> None:
    """A second call with another box duration would mix two studies: refused, naming the field; the same is fine."""
    cfg = replace(box_study_smoke_cfg(str(tmp_path)), num_trials=1, models=("rigid",))
    run(cfg)
    longer = replace(cfg, box=replace(cfg.box, duration=cfg.box.duration + 0.1))
    with pytest.raises(ValueError, match=r"box\.duration"):
        run(longer)
    with pytest.raises(ValueError, match=r"mpm\.max_iterations"):
        run(replace(cfg, mpm=replace(cfg.mpm, max_iterations=cfg.mpm.max_iterations + 1)))
    assert len(StudyRecords(tmp_path).rows()) == 1
    run(replace(cfg, models=("rigid", "rft3d"), max_minutes=1.0))  # other models / time box: allowed
    assert len(StudyRecords(tmp_path).rows()) == 2


def test_mpm_smoke_trials_batched_and_scored(tmp_path: Path) -> None:
    """Run two MPM trials in one solve (tiny beds, 0.2 s) plus Rigid and 3D-RFT: matched, scored and timed.

    Each trial's trajectory is expressed in its own region's frame (it starts at the box's initial position).
    """
    cfg = replace(box_study_smoke_cfg(str(tmp_path)), num_trials=2, mpm_batch=2, models=("mpm", "rigid", "rft3d"))
    summary = run(cfg)
    fwd = summary["variants"]["forward"]
    assert fwd["mpm_trials_done"] == 2
    assert fwd["scores"]["rft3d"]["matched_trials"] == 2
    assert fwd["timing"]["mpm"]["particle_count"] > 0 and fwd["timing"]["mpm"]["frames_per_s_median"] > 0
    series = [s for s in StudyRecords(tmp_path).series() if s["model"] == "mpm"]
    assert len(series) == 2 and all(len(s["grf"]) == round(cfg.box.duration / cfg.mpm.frame_dt) for s in series)
    for s in series:  # first frame: 1 cm along +x from the launch point, still in the air
        np.testing.assert_allclose(s["pos"][0][:2], [0.01, 0.0], atol=2e-3)
    rows = [r for r in StudyRecords(tmp_path).rows() if r["model"] == "mpm"]
    assert all(0.05 < r["travel"] < 0.3 for r in rows)  # 0.2 s launched at 1 m/s, slowed by the sand


def test_size_variants_bookkeeping(tmp_path: Path) -> None:
    """size_x<scale> variants: same mass, scaled footprint; summary carries a size-sensitivity block."""
    from gmloco.eval.box.study import _variant_box

    cfg = replace(box_study_smoke_cfg(str(tmp_path)), num_trials=2, variants=("forward", "size_x0.5"),
                  models=("rigid", "rft3d"))  # fmt: skip
    small = _variant_box(cfg, "size_x0.5")
    assert small.mass == cfg.box.mass and small.size == (0.15, 0.15, 0.2)
    summary = run(cfg)
    sens = summary["size_sensitivity"]
    assert set(sens["variants"]) == {"forward", "size_x0.5"}
    assert sens["best_model_stable"]["travel_rel_err_median"] is None  # no MPM reference in this call
    # 3D-RFT: the same weight on a quarter of the area sinks deeper
    rows = StudyRecords(tmp_path).rows()
    sink = {r["variant"]: r["sinkage"] for r in rows if r["model"] == "rft3d" and r["trial"] == 0}
    assert sink["size_x0.5"] > sink["forward"]
    with pytest.raises(ValueError, match="size_x"):
        _variant_box(cfg, "size_xbig")


def _fake_mpm_dir(path: Path, voxel: float, travel: list[float], sinkage: list[float]) -> Path:
    """Write MPM-only study records with given per-trial travel and sinkage."""
    rec = StudyRecords(path)
    for t, (tr, sk) in enumerate(zip(travel, sinkage, strict=True)):
        row = {"variant": "forward", "trial": t, "model": "mpm", "travel": tr, "sinkage": sk, "lateral_force": 0.0,
               "peak_fz": 0.0, "wall_s": 1.0, "frames_per_s": 50.0, "particle_count": 10, "voxel_size": voxel}  # fmt: skip
        rec.append(row, {"time": np.zeros(1), "grf": np.zeros((1, 3)), "pos": np.zeros((1, 3))})
    return path


def test_voxel_convergence_hand_values(tmp_path: Path) -> None:
    """Differences to the finest voxel size, per trial then median; converged by the stated tolerances."""
    from gmloco.eval.box.checks import voxel_convergence

    d5 = _fake_mpm_dir(tmp_path / "v5", 0.05, [0.30, 0.40, 0.50], [0.020, 0.030, 0.040])
    d3 = _fake_mpm_dir(tmp_path / "v3", 0.03, [0.21, 0.32, 0.41], [0.012, 0.022, 0.033])
    d2 = _fake_mpm_dir(tmp_path / "v2", 0.02, [0.20, 0.30, 0.40], [0.010, 0.020, 0.030])
    res = voxel_convergence([d3, d2, d5])
    assert [lv["voxel_size"] for lv in res["levels"]] == [0.05, 0.03, 0.02]
    # 3 cm vs 2 cm: travel 0.01/0.2 = 0.05, 0.02/0.3 = 0.067, 0.01/0.4 = 0.025 -> median 0.05; sinkage 2, 2, 3 mm
    np.testing.assert_allclose(res["levels"][1]["travel_rel_diff_to_finest"], 0.05)
    np.testing.assert_allclose(res["levels"][1]["sinkage_abs_diff_to_finest"], 0.002)
    # 5 cm: travel 0.5, 0.333, 0.25 -> 0.333; sinkage 10 mm each
    np.testing.assert_allclose(res["levels"][0]["travel_rel_diff_to_finest"], 1 / 3)
    assert res["converged"] is True  # 0.05 <= 0.1 and 2 mm <= 5 mm
    assert voxel_convergence([d5, d2])["converged"] is False


def test_roll_variant_geometry() -> None:
    """Rolled 15 deg about x: quaternion (cos 7.5, sin 7.5, 0, 0); lowest edge drop_height above the surface."""
    from gmloco.eval.box.config import BoxCfg, box_roll_variant

    box = box_roll_variant(BoxCfg(), 15.0)
    c, s = np.cos(np.radians(7.5)), np.sin(np.radians(7.5))
    np.testing.assert_allclose(box.initial_quat_wxyz, [c, s, 0.0, 0.0], atol=1e-12)
    # lowest point: hy sin 15 + hz cos 15 = 0.15 * 0.2588 + 0.1 * 0.9659 = 0.13541 m below the CoM
    np.testing.assert_allclose(box.initial_pos[2], 0.1 + 0.13541, atol=1e-5)
    np.testing.assert_allclose(BoxCfg().initial_pos, [0.0, 0.0, 0.2])  # unrotated box unchanged


def _impact_series(f_lat: list[float], weight: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """10 samples of 10 ms: airborne for 3, then 4 samples in contact (F_z = m g, F_y = f_lat), then at rest."""
    time = 0.01 * np.arange(1, 11)
    grf = np.zeros((10, 3))
    grf[3:7, 2] = weight
    grf[3:7, 1] = f_lat
    x = 0.01 * np.minimum(np.arange(1, 11), 7)  # 1 m/s until sample 6, then at rest
    pos = np.stack([x, np.zeros(10), np.zeros(10)], axis=-1)
    return time, grf, pos


def test_lateral_impact_hand_values() -> None:
    """Peak and impulse of |F_lat| over the impact window; the time mean (old metric) and signed impulse are 0."""
    from gmloco.eval.box.checks import impact_window, lateral_impact
    from gmloco.eval.metrics.box import metric_lateral_force

    weight = 35.0 * 9.81
    time, grf, pos = _impact_series([50.0, -50.0, 50.0, -50.0], weight)
    assert impact_window(time, grf, pos, weight) == (3, 7)
    m = lateral_impact(time, grf, pos, (1.0, 0.0), weight)  # lateral axis e_z x e_x = +y
    np.testing.assert_allclose(m["peak_lateral_over_mg"], 50.0 / weight)
    np.testing.assert_allclose(m["lateral_impulse_abs"], 4 * 50.0 * 0.01)
    np.testing.assert_allclose([m["lateral_impulse"], m["impact_duration"]], [0.0, 0.04], atol=1e-12)
    assert metric_lateral_force(grf, (1.0, 0.0)) == 0.0
    # launched along +y the lateral axis is -x: a force along -x is lateral, one along y is not
    g2 = grf[:, [1, 0, 2]] * np.array([-1.0, 1.0, 1.0])
    m2 = lateral_impact(time, g2, pos[:, [1, 0, 2]], (0.0, 1.0), weight)
    np.testing.assert_allclose(m2["lateral_impulse_abs"], 2.0)
    air = lateral_impact(time, np.zeros((10, 3)), pos, (1.0, 0.0), weight)
    assert air["impact_duration"] == 0.0 and air["peak_lateral_over_mg"] == 0.0


def test_lateral_impact_summary_scores_against_mpm(tmp_path: Path) -> None:
    """Per-model medians and errors against MPM on matched trials; ties with the best are listed."""
    from gmloco.eval.box.checks import lateral_impact_summary

    weight = 35.0 * 9.81
    rec = StudyRecords(tmp_path)
    for model, f in (("mpm", 20.0), ("a", 20.0), ("b", 80.0), ("c", 0.0)):
        time, grf, pos = _impact_series([f, -f, f, -f], weight)
        row = {"variant": "lateral", "trial": 0, "model": model, "travel": 0.1, "sinkage": 0.01,
               "lateral_force": 0.0, "peak_fz": weight, "wall_s": 1.0, "frames_per_s": 1.0, "particle_count": 0,
               "voxel_size": 0.0}  # fmt: skip
        rec.append(row, {"time": time, "grf": grf, "pos": pos})
    out = lateral_impact_summary(rec, {"lateral": (1.0, 0.0)}, weight)["lateral"]
    np.testing.assert_allclose(out["models"]["b"]["peak_lateral_err_median"], 60.0 / weight)
    np.testing.assert_allclose(out["models"]["b"]["impulse_rel_err_median"], (3.2 - 0.8) / 0.8)
    np.testing.assert_allclose(out["models"]["c"]["impulse_rel_err_median"], 1.0)
    assert out["best"]["peak_lateral_err_median"] == "a" and out["models"]["a"]["peak_lateral_err_median"] == 0.0
    assert out["within_1pct_of_best"]["drift_abs_err_median"] == ["a", "b", "c"]  # no model drifts sideways


def test_voxel_convergence_lists_failed_level(tmp_path: Path) -> None:
    """A level without MPM records (the solve failed) is listed with its log's error, the others compared."""
    from gmloco.eval.box.checks import write_voxel_convergence

    d5 = _fake_mpm_dir(tmp_path / "v5", 0.05, [0.30, 0.40], [0.020, 0.030])
    d3 = _fake_mpm_dir(tmp_path / "v3", 0.03, [0.21, 0.32], [0.012, 0.022])
    bad = tmp_path / "v2"
    bad.mkdir()
    (bad / "config.json").write_text(json.dumps({"mpm": {"voxel_size": 0.02, "max_iterations": 250}}))
    (tmp_path / "v2.log").write_text("Traceback (most recent call last):\n  ...\nAssertionError: sand leaked\n")
    res = write_voxel_convergence([d5, d3, bad], tmp_path / "out" / "convergence.json")
    assert [lv["voxel_size"] for lv in res["levels"]] == [0.05, 0.03]
    assert res["failed_levels"] == [
        {"dir": str(bad), "voxel_size": 0.02, "max_iterations": 250, "error": "AssertionError: sand leaked"}
    ]
    assert json.loads((tmp_path / "out" / "convergence.json").read_text())["converged"] is False
    with pytest.raises(ValueError, match="holds MPM trials"):
        write_voxel_convergence([bad], tmp_path / "x.json")


def test_failed_mpm_solve_is_logged_and_skipped(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A solve failing its physical checks: diagnostics logged, its trials left out, the next batch still runs."""
    from gmloco.eval.mpm.box_scene import MpmBoxScene

    real = MpmBoxScene.test_final
    calls = []

    def fail_first(self: MpmBoxScene, max_leaked_fraction: float = 0.0) -> dict:
        calls.append(1)
        if len(calls) == 1:
            raise AssertionError("sand leaked through the floor: test")
        return real(self, max_leaked_fraction)

    monkeypatch.setattr(MpmBoxScene, "test_final", fail_first)
    cfg = replace(box_study_smoke_cfg(str(tmp_path)), num_trials=2, mpm_batch=1, models=("mpm",),
                  box=replace(box_study_smoke_cfg(str(tmp_path)).box, duration=0.05))  # fmt: skip
    summary = run(cfg)
    assert [r["trial"] for r in StudyRecords(tmp_path).rows()] == [1]
    assert summary["complete"] is False
    (fail,) = summary["mpm_failures"]
    assert fail["trials"] == [0] and fail["variant"] == "forward" and fail["leaked_particles"] == 0
    assert "test" in fail["error"] and fail["leaked_per_region"] == [0]
