# SPDX-License-Identifier: Apache-2.0
"""Voxel study read-outs on hand-made sole records with closed-form answers (linear press, set drag and lift-off)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from gmloco.eval.calibration.dataset import CalibrationDataset, save_dataset
from gmloco.eval.calibration.protocol import SoleProtocolCfg, SoleRecord
from gmloco.eval.calibration.voxel_study import main

WEIGHT = 35.0 * 9.81
"""Single-stance G1 load of the default protocol [N] (343.35 N)."""
ONSET = 0.02 * WEIGHT
"""Default onset force [N] (6.867 N)."""
H = 0.002
"""Height of the synthetic felt surface above the nominal top [m]: F_z = k (depth + H) above 0."""
STEP = 0.0005
"""Press descent per frame [m] (5 cm/s at 10 ms)."""


def _record(depth: np.ndarray, force: np.ndarray, phase: np.ndarray) -> SoleRecord:
    """Return a record with the given depth [m] [T], force [N] [T, 3] and phase [T]; the rest kinematically empty."""
    t = len(depth)
    pos = np.zeros((t, 3))
    pos[:, 2] = -depth
    zeros = np.zeros((t, 3))
    return SoleRecord(0.01 * np.arange(t), pos, np.tile(np.eye(3), (t, 1, 1)), zeros, zeros, force, depth, phase)


def _press(k: float, first: float = -0.005, last: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    """Return depth [m] and force [N] [T, 3] of a linear press F_z = k (depth + H), 0 above the felt surface."""
    depth = np.arange(first, last + 1e-9, STEP)
    force = np.zeros((len(depth), 3))
    force[:, 2] = np.maximum(0.0, k * (depth + H))
    return depth, force


def _records(k: float) -> dict[str, SoleRecord]:
    """Return press, drag, liftoff and repeat records of stiffness ``k`` [N/m]."""
    depth, force = _press(k)
    press = _record(depth, force, np.zeros(len(depth), dtype=np.int64))
    # drag phases: press, hold, move, hold; second half of the move: F = (-30, 0, 60) N
    move = np.zeros((10, 3))
    move[:5] = (-90.0, 0.0, 200.0)
    move[5:] = (-30.0, 0.0, 60.0)
    drag = _record(np.full(12, 0.005), np.vstack([np.zeros((2, 3)), move]), np.array([0, 1] + [2] * 10))
    # lift-off phases: press, hold, move up 1 mm a frame; F_z falls below ONSET at the 4th lift frame (3 mm up)
    lift_fz = np.array([300.0, 100.0, 20.0, -5.0, -2.0, 0.0])
    lift_depth = 0.01 - 0.001 * np.arange(6)
    liftoff = _record(np.r_[0.01, 0.01, lift_depth], np.c_[np.zeros((8, 2)), np.r_[400.0, 350.0, lift_fz]],
                      np.array([0, 1] + [2] * 6))  # fmt: skip
    # repeat: three (press, hold, lift) steps reaching the weight at 1.0, 1.2 and 1.5 cm
    parts = []
    for step, at in enumerate((0.010, 0.012, 0.015)):
        d = np.array([at - STEP, at + STEP])
        parts += [(d, [WEIGHT - 100.0, WEIGHT + 100.0], 3 * step), (d[1:], [WEIGHT], 3 * step + 1)]
        parts.append((np.array([0.0]), [0.0], 3 * step + 2))
    rep_depth = np.concatenate([p[0] for p in parts])
    rep_force = np.zeros((len(rep_depth), 3))
    rep_force[:, 2] = np.concatenate([p[1] for p in parts])
    phases = np.concatenate([np.full(len(p[0]), p[2]) for p in parts]).astype(np.int64)
    return {"press": press, "drag": drag, "liftoff": liftoff, "repeat": _record(rep_depth, rep_force, phases)}


def _write(folder: Path, k: float, voxel: float | None) -> Path:
    """Write ``folder/dry_sand.npz`` of stiffness ``k`` [N/m] made at ``voxel`` [m] (None: no MPM settings)."""
    records = _records(k)
    extra = {"mpm": {"solver": {"voxel_size": voxel}}, "timings": {"press": {"particle_count": 8}}} if voxel else {}
    ds = CalibrationDataset("dry_sand", {"rho_c": 2000.0}, "mpm", SoleProtocolCfg(), records,
                            dict.fromkeys(records, "fit"), 0, extra=extra)  # fmt: skip
    return save_dataset(ds, folder / "dry_sand.npz")


def test_voxel_study_closed_forms(tmp_path: Path) -> None:
    """Depth at the weight, onset, forces, drag, suction, repeat growth and their changes match the closed forms."""
    _write(tmp_path / "fine", 20000.0, 0.01)
    _write(tmp_path / "coarse", 25000.0, 0.02)
    out = tmp_path / "study" / "summary.json"
    args = ["--datasets", str(tmp_path / "coarse"), str(tmp_path / "fine"), "--materials", "dry_sand"]
    assert main([*args, "--out", str(out)]) == 0
    body = json.loads(out.read_text())
    fine, coarse = body["materials"]["dry_sand"]["0.01"], body["materials"]["dry_sand"]["0.02"]
    assert list(body["materials"]["dry_sand"]) == ["0.01", "0.02"]  # sorted finest first
    # F_z = k (d + H) = W  ->  d = W / k - H: 343.35 / 20000 - 0.002 = 0.0151675 m
    np.testing.assert_allclose(fine["weight_depth_m"], WEIGHT / 20000.0 - H, atol=1e-12)
    np.testing.assert_allclose(coarse["weight_depth_m"], WEIGHT / 25000.0 - H, atol=1e-12)
    # onset: k (d + H) = 6.867 N  ->  height -d = H - 6.867 / 20000 = 0.00165665 m; felt depth = (W - 6.867) / k
    np.testing.assert_allclose(fine["onset"]["height_m"], H - ONSET / 20000.0, atol=1e-12)
    assert fine["onset"]["censored"] is False
    np.testing.assert_allclose(fine["felt_weight_depth_m"], (WEIGHT - ONSET) / 20000.0, atol=1e-12)
    # force at 0.5 cm: 20000 * 0.007 = 140 N; 4 cm lies beyond the press
    np.testing.assert_allclose(fine["force_at_depth_N"]["0.005"], 140.0, rtol=1e-9)
    assert fine["force_at_depth_N"]["0.04"] is None and fine["particle_count"] == 8
    np.testing.assert_allclose([fine["drag"]["lateral_N"], fine["drag"]["lateral_over_vertical"]], [30.0, 0.5])
    assert fine["drag_fast"] is None
    np.testing.assert_allclose([fine["liftoff"]["suction_N"], fine["liftoff"]["release_lift_m"]], [5.0, 0.003])
    np.testing.assert_allclose(fine["repeat"]["depths_at_weight_m"], [0.010, 0.012, 0.015], atol=1e-12)
    np.testing.assert_allclose(fine["repeat"]["growth_m"], 0.005, atol=1e-12)
    pair = body["convergence"]["dry_sand"]["pairs"]["0.02_vs_0.01"]
    # (W / 25000 - H) / (W / 20000 - H) - 1 = 0.0117340 / 0.0151675 - 1 = -0.22637
    d1, d2 = WEIGHT / 20000.0 - H, WEIGHT / 25000.0 - H
    np.testing.assert_allclose(pair["weight_depth_rel_change"], (d2 - d1) / d1, rtol=1e-9)
    np.testing.assert_allclose(pair["force_rel_change_at_depth"]["0.005"], 0.25, rtol=1e-9)  # 175 / 140 - 1
    assert body["convergence"]["dry_sand"]["finest_pair_converged"] is False  # 25 % > 20 %
    assert (out.parent / "force_depth_by_voxel.png").stat().st_size > 1000


def test_voxel_study_rejects_bad_input(tmp_path: Path) -> None:
    """A dataset without an MPM voxel size, two folders of one voxel size, or a missing file exit 2."""
    _write(tmp_path / "a", 20000.0, 0.01)
    _write(tmp_path / "b", 25000.0, 0.01)
    _write(tmp_path / "none", 20000.0, None)
    base = ["--materials", "dry_sand", "--no-figures", "--out", str(tmp_path / "s.json"), "--datasets"]
    assert main([*base, str(tmp_path / "a"), str(tmp_path / "b")]) == 2
    assert main([*base, str(tmp_path / "none")]) == 2
    assert main([*base, str(tmp_path / "missing")]) == 2
    assert not (tmp_path / "s.json").exists()
