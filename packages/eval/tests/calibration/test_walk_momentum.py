# SPDX-License-Identifier: Apache-2.0
"""The sand force from the robot's momentum: against MuJoCo's own contact forces, the foot split, a real walk."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gmloco.eval.calibration.walk_momentum import MomentumForceCfg, foot_forces, total_force

WALK = (
    Path(__file__).resolve().parents[4]
    / "results/mpm_eval/table_rows/dry_sand_square_window/runs/table_td_dry_sand_sq_share0of4/recordings"
    / "dry_sand__straight__v1.mcap"
)
"""The td student's first 1.0 m/s walk on MPM dry sand (3 cm voxels), logged with the aliased per-foot force."""


def _squat_on_the_plane() -> tuple[object, np.ndarray, np.ndarray, np.ndarray, float]:
    """The G1 dropped 2 cm onto MuJoCo's plane, squatting at 2 Hz under PD: 50 Hz samples and the true mean force.

    Returns (model, qpos [T, nq], qvel [T, nv], true mean contact force over [t_k-1, t_k+1] [T, 3], frame dt).
    """
    import mujoco

    from gmloco.deploy.g1 import G1_DAMPING, G1_JOINT_NAMES, G1_KNEES_BENT_POSE, G1_STIFFNESS
    from gmloco.deploy.mismatch.g1model import build_model

    model = build_model()
    data = mujoco.MjData(model)
    q0 = np.asarray(G1_KNEES_BENT_POSE, dtype=float)
    data.qpos[2], data.qpos[3], data.qpos[7:] = 0.80, 1.0, q0
    knee = [i for i, n in enumerate(G1_JOINT_NAMES) if "knee" in n]
    hip = [i for i, n in enumerate(G1_JOINT_NAMES) if "hip_pitch" in n]
    sub = round(0.02 / model.opt.timestep)
    kp, kd = np.asarray(G1_STIFFNESS), np.asarray(G1_DAMPING)
    qpos, qvel, force = [], [], []
    for _ in range(60):
        qpos.append(data.qpos.copy())
        qvel.append(data.qvel.copy())
        f = np.zeros(3)
        for _step in range(sub):
            target = q0.copy()
            s = 0.25 * np.sin(2.0 * np.pi * 2.0 * data.time)
            target[knee] += 2 * s
            target[hip] -= s
            data.ctrl[:] = 0.0
            data.qfrc_applied[6:] = kp * (target - data.qpos[7:]) - kd * data.qvel[6:]
            mujoco.mj_step(model, data)
            mujoco.mj_rnePostConstraint(model, data)
            f += data.cfrc_ext[1:, 3:].sum(axis=0) / sub
        force.append(f)
    step = np.asarray(force)  # mean over [t_k, t_k+1]
    mean = np.full_like(step, np.nan)
    mean[1:-1] = 0.5 * (step[:-2] + step[1:-1])  # [t_k-1, t_k+1]
    return model, np.asarray(qpos), np.asarray(qvel), mean, 0.02


def test_total_force_is_the_contact_force_mujoco_applied() -> None:
    """On the plane the momentum's force equals MuJoCo's contact force, averaged alike, within 2 % of the weight."""
    model, qpos, qvel, truth, dt = _squat_on_the_plane()
    got = total_force(model, qpos, qvel, dt)
    weight = float(model.body_subtreemass[0]) * 9.81
    assert np.isnan(got[[0, -1]]).all()
    assert np.ptp(truth[1:-1, 2]) > 0.3 * weight  # the landing and the squat move the force, not a still stance
    np.testing.assert_allclose(got[1:-1], truth[1:-1], atol=0.02 * weight)


def test_single_support_gives_the_total_to_the_stance_foot() -> None:
    """Left alone on frames k-1..k+1: left carries the total, right none; double support and edges are NaN."""
    total = np.tile([1.0, 2.0, 300.0], (6, 1))
    logged = np.zeros((6, 2, 3))
    logged[:, 0, 2] = 100.0  # left always loaded
    logged[[0, 4, 5], 1, 2] = 100.0  # right loaded at 0, 4, 5: clear on 1-3
    depth = np.full((6, 2), 0.04)
    depth[:, 1] = -0.02  # right above the bed's top
    out = foot_forces(total, logged, depth, MomentumForceCfg(contact_force=40.0))
    assert np.isnan(out[[0, 1, 3, 4, 5]]).all()  # only frame 2 has a clear right foot on frames 1, 2 and 3
    np.testing.assert_array_equal(out[2, 0], total[2])
    np.testing.assert_array_equal(out[2, 1], 0.0)
    depth[2, 1] = 0.01  # unloaded but still in its footprint on frame 2: no frame is single support
    assert np.isnan(foot_forces(total, logged, depth)).all()


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.skipif(not WALK.is_file(), reason="committed MPM recording not in this checkout")
def test_a_recorded_walk_is_carried_by_its_weight() -> None:
    """The td student's MPM walk: the momentum carries 0.99 of the weight; the aliased log carried 0.70."""
    from gmloco.eval.calibration.walk_records import WalkRecordsCfg, foot_records

    logged, momentum = foot_records(WALK), foot_records(WALK, WalkRecordsCfg(force_source="momentum"))
    weight = 33.341142 * 9.81
    fz_logged = (logged["left"].force[:, 2] + logged["right"].force[:, 2]).mean() / weight
    both = np.stack([momentum["left"].force, momentum["right"].force], axis=1)
    single = np.isfinite(both).all(axis=(1, 2))
    assert 0.15 < single.mean() < 0.35 and abs(fz_logged - 0.70) < 0.01
    fz = both[single, :, 2].sum(axis=1)
    assert 0.9 < fz.mean() / weight < 1.1  # a stance foot carries the robot on average
    assert (both[single].min(axis=1)[:, 2] == 0.0).all()  # the clear foot carries nothing


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.skipif(not WALK.is_file(), reason="committed MPM recording not in this checkout")
def test_the_aliased_log_reads_part_of_the_stance_force() -> None:
    """On the committed walk (logged before the step mean) the log reads ~0.8 of the momentum's stance force."""
    from gmloco.eval.calibration.walk_records import logged_over_momentum

    assert 0.6 < logged_over_momentum(WALK) < 0.95


def test_errors_leave_out_frames_without_a_force() -> None:
    """A frame whose force is unknown (NaN) counts in no split's RMS; a split of unknown frames only is NaN."""
    from types import SimpleNamespace

    from gmloco.eval.calibration.fit import rms_by_split

    ds = SimpleNamespace(split={"a": "fit", "b": "fit", "c": "heldout"})
    sq = {"a": np.array([9.0, np.nan]), "b": np.array([16.0]), "c": np.array([np.nan, np.nan])}
    out = rms_by_split(ds, sq)  # type: ignore[arg-type]
    assert out["fit"] == pytest.approx(np.sqrt(12.5)) and np.isnan(out["heldout"])


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.skipif(not WALK.is_file(), reason="committed MPM recording not in this checkout")
def test_a_momentum_walk_dataset_replays_to_finite_errors() -> None:
    """The published sand replayed on a momentum walk: finite errors over the single-support frames alone."""
    from gmloco.contact import RftExtensionsCfg
    from gmloco.eval.calibration.fit import SandFitCfg, split_error
    from gmloco.eval.calibration.walk_records import WalkRecordsCfg, walk_dataset

    ds = walk_dataset([WALK], "dry_sand", WalkRecordsCfg(force_source="momentum"))
    assert ds.extra["walk_records"]["force_source"] == "momentum"
    splits, per = split_error(ds, RftExtensionsCfg(), SandFitCfg(params=()))
    known = [v for v in splits.values() if np.isfinite(v)]
    assert known and all(0.0 < v < 2000.0 for v in known) and all(np.isfinite(v) for v in per.values())
