# SPDX-License-Identifier: Apache-2.0
"""The twist experiment (yaw torque of loaded sand) on the float64 3D-RFT reference, its dataset and its fit term."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, RftExtensionsCfg
from gmloco.eval.calibration.build import CalibrationBuildCfg, build_dataset
from gmloco.eval.calibration.dataset import assign_split, load_dataset, save_dataset
from gmloco.eval.calibration.fit import SandFitCfg, fit_extensions, replay_wrenches, torque_scale
from gmloco.eval.calibration.protocol import EXPERIMENTS, SoleProtocolCfg, SoleRecord, run_experiment
from gmloco.eval.calibration.rft_sand import centred_sole_collider, rft_sole_sand

FAST = SoleProtocolCfg(time_scale=0.5)
"""Phases halved (a 0.13 s turn at 1 rad/s)."""
YAW_PHASES = (2, 3, 4)
"""Phase indices of the twist's turns: +rate, -rate, +rate."""


def _run(name: str, lateral_scale: float = 1.0, protocol: SoleProtocolCfg = FAST) -> SoleRecord:
    """Run one experiment on the reference sand (plain RFT, dry sand) with ``lateral_scale``."""
    model = ContactRFT3DCfg(at_rest="none", extensions=RftExtensionsCfg(lateral_scale=lateral_scale, dt=0.01))
    sand = rft_sole_sand(centred_sole_collider(protocol, "box", 3), model, MATERIAL_PRESETS["dry_sand"])
    return run_experiment(name, protocol, sand)


def test_twist_torque_opposes_rotation() -> None:
    """Loaded and turned about the vertical, the sand's yaw torque opposes the yaw rate in every turning frame."""
    rec = _run("twist")
    assert rec.has_torque
    turning = np.isin(rec.phase, YAW_PHASES)
    assert sorted(set(np.sign(rec.ang_vel[turning, 2]))) == [-1.0, 1.0]
    tau, rate = rec.torque[turning, 2], rec.ang_vel[turning, 2]
    assert np.all(tau * rate < 0.0)
    assert np.abs(tau).min() > 0.1  # N m: a resisting torque, not round-off
    # the turn is about the sole centre at the load's depth: centre and lowest point stay put, the yaw comes back
    loaded = np.flatnonzero(turning)[0]
    np.testing.assert_allclose(rec.pos[turning], np.broadcast_to(rec.pos[loaded], rec.pos[turning].shape))
    np.testing.assert_allclose(rec.depth[turning], rec.depth[loaded], atol=1e-12)
    assert rec.force[loaded - 1, 2] >= FAST.weight  # pressed to the single-stance load first
    yaw_end = np.sum(rec.ang_vel[:, 2]) * FAST.frame_dt
    assert abs(yaw_end) < 1e-12
    np.testing.assert_allclose(np.arctan2(rec.rot[turning, 1, 0], rec.rot[turning, 0, 0]).max(), FAST.twist_angle / 2,
                               atol=FAST.twist_rate * FAST.frame_dt)  # fmt: skip


def test_twist_torque_scales_with_lateral_scale() -> None:
    """The yaw torque comes from horizontal element forces only: linear in the lateral scale; F_z is untouched."""
    ref = _run("twist", 1.0)
    for scale in (0.2, 0.5):
        rec = _run("twist", scale)
        np.testing.assert_allclose(rec.torque[:, 2], scale * ref.torque[:, 2], rtol=1e-9, atol=1e-12)
        np.testing.assert_array_equal(rec.force[:, 2], ref.force[:, 2])


def test_press_has_no_yaw_torque() -> None:
    """A pure press (and the twist's press and hold) carries no yaw torque; the twist's net horizontal force is ~0."""
    press = _run("press")
    assert press.has_torque and np.abs(press.torque).max() < 1e-9
    twist = _run("twist")
    assert np.abs(twist.torque[~np.isin(twist.phase, YAW_PHASES), 2]).max() < 1e-9
    # a symmetric sole turning about its centre: no net horizontal force beyond the RFT's v.n = 0 edge elements
    assert np.abs(twist.force[:, :2]).max() < 1e-3 * FAST.weight


# Before the twist: (frames, a middle frame, force there [N], force at the last frame [N]) of each experiment on the
# plain reference sand (CalibrationBuildCfg(sand="rft3d_reference", protocol=FAST), resolution 3)
PINNED: dict[str, tuple[int, int, tuple[float, float, float], tuple[float, float, float]]] = {
    "press": (54, 27, (8.673617379884035e-19, 1.734723475976807e-18, 178.64244386205212),
              (0.0, -6.938893903907228e-18, 357.3772493883404)),
    "press_fast": (22, 11, (-3.469446951953614e-18, 0.0, 357.37724938834026),
                   (8.239936510889834e-18, -7.806255641895632e-18, 399.45293266781067)),
    "tilt": (90, 45, (16.389499928523477, 0.0, 101.8491990845847), (8.07162899340255, 0.0, 66.33129202521933)),
    "drag": (98, 49, (-10.051083039237767, -1.734723475976807e-18, 24.201391782639483),
             (-2.6020852139652106e-18, 0.0, 189.1562559518336)),
    "drag_fast": (40, 20, (-12.705854925905342, 0.0, 29.742312093101447),
                  (1.734723475976807e-18, 3.469446951953614e-18, 231.21150431096004)),
    "liftoff": (84, 42, (3.469446951953614e-18, 6.938893903907228e-18, 336.34962520877707), (0.0, 0.0, 0.0)),
    "repeat": (284, 142, (3.469446951953614e-18, -6.938893903907228e-18, 336.3496252087771), (0.0, 0.0, 0.0)),
}  # fmt: skip


def test_existing_experiments_unchanged(tmp_path: Path) -> None:
    """The experiments other than twist keep their order, frame counts and forces; seed 0 keeps their split."""
    assert EXPERIMENTS[:7] == tuple(PINNED) and EXPERIMENTS[7:] == ("twist",)
    cfg = CalibrationBuildCfg(out_dir=str(tmp_path), sand="rft3d_reference", protocol=FAST)
    ds = load_dataset(build_dataset(cfg)[0])
    for name, (frames, mid, f_mid, f_end) in PINNED.items():
        rec = ds.records[name]
        assert len(rec.time) == frames, name
        np.testing.assert_allclose(rec.force[mid], f_mid, rtol=1e-10, atol=1e-9, err_msg=name)
        np.testing.assert_allclose(rec.force[-1], f_end, rtol=1e-10, atol=1e-9, err_msg=name)
        assert rec.has_torque, name
    seven = assign_split(list(PINNED), 0)
    assert {n: ds.split[n] for n in PINNED} == seven and ds.split["twist"] == "fit"


def test_twist_round_trips_and_forces_only_files_load(tmp_path: Path) -> None:
    """The torque is saved and read back; a file without torques loads as forces-only records."""
    cfg = CalibrationBuildCfg(out_dir=str(tmp_path), sand="rft3d_reference", protocol=FAST,
                              experiments=("press", "twist"))  # fmt: skip
    path = build_dataset(cfg)[0]
    ds = load_dataset(path)
    np.testing.assert_array_equal(ds.records["twist"].torque, _run("twist").torque)
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files if not k.endswith("/torque")}
    old = tmp_path / "forces_only.npz"
    np.savez_compressed(old, **arrays)  # pyright: ignore[reportArgumentType]
    bare = load_dataset(old)
    assert not bare.records["twist"].has_torque and bare.records["twist"].torque.shape == (0, 3)
    np.testing.assert_array_equal(bare.records["twist"].force, ds.records["twist"].force)


def test_fit_reads_lateral_scale_from_the_twist_torque(tmp_path: Path) -> None:
    """A twisted sole's net horizontal force is ~0: the torque residual is what informs the lateral scale."""
    truth = RftExtensionsCfg(lateral_scale=0.3)
    cfg = CalibrationBuildCfg(out_dir=str(tmp_path), sand="rft3d_reference", protocol=FAST, reference_extensions=truth,
                              experiments=("press", "twist"))  # fmt: skip
    ds = load_dataset(build_dataset(cfg)[0])
    ds = replace(ds, split={"press": "heldout", "twist": "fit"})
    fit = SandFitCfg(params=("lateral_scale",), plastic_unloading="off", at_rest="none", fit_datum=False)
    with_torque = fit_extensions(ds, fit)
    np.testing.assert_allclose(with_torque.extensions.lateral_scale, 0.3, rtol=1e-4)
    assert with_torque.torque_error_before is not None and with_torque.torque_error_after is not None
    assert with_torque.torque_error_before["fit"] > 0.5  # N m: the published model resists the turn 1 / 0.3 x
    assert with_torque.torque_error_after["fit"] < 1e-3 * with_torque.torque_error_before["fit"]
    assert with_torque.per_record["twist"]["torque_after"] < 1e-3
    # residual change from lateral scale 1 to 0.3 along the twist: force part (over W) vs torque part (over W l)
    one, truth_wrench = (
        replay_wrenches(ds, RftExtensionsCfg(lateral_scale=k), fit, ["twist"])["twist"] for k in (1, 0.3)
    )
    force_part = np.linalg.norm(one[:, :3] - truth_wrench[:, :3]) / ds.protocol.weight
    torque_part = np.linalg.norm(one[:, 5] - truth_wrench[:, 5]) / torque_scale(ds)
    assert torque_part > 100.0 * force_part


def test_bad_input_raises(tmp_path: Path) -> None:
    """A non-positive twist rate or angle, an unknown experiment, a force-only sand or torque weight < 0 is refused."""
    with pytest.raises(ValueError, match="twist_rate must be > 0"):
        SoleProtocolCfg(twist_rate=-1.0)
    with pytest.raises(ValueError, match="twist_angle must be > 0"):
        SoleProtocolCfg(twist_angle=0.0)
    with pytest.raises(ValueError, match="unknown experiment 'spin'"):
        _run("spin")
    with pytest.raises(ValueError, match="unknown experiments"):
        build_dataset(CalibrationBuildCfg(out_dir=str(tmp_path), sand="rft3d_reference", experiments=("spin",)))
    with pytest.raises(ValueError, match=r"wrench \(force, torque\) \[6\]"):
        run_experiment("twist", FAST, lambda pos, rot, lin, ang: np.zeros(3))
    with pytest.raises(ValueError, match="torque_weight"):
        SandFitCfg(torque_weight=-1.0)
    from gmloco.eval.calibration.__main__ import main

    with pytest.raises(SystemExit) as exit_info:
        main(["--experiments", "spin", "--sand", "rft3d_reference", "--out", str(tmp_path)])
    assert exit_info.value.code == 2


def test_saved_forces_only_record_round_trips(tmp_path: Path) -> None:
    """A record built without a torque (empty) is written and read back as forces only."""
    rec = replace(_run("press"), torque=np.zeros((0, 3)))
    ds = load_dataset(build_dataset(CalibrationBuildCfg(out_dir=str(tmp_path), sand="rft3d_reference", protocol=FAST,
                                                        experiments=("press",)))[0])  # fmt: skip
    path = save_dataset(replace(ds, records={"press": rec}), tmp_path / "bare" / "dry_sand.npz")
    assert not load_dataset(path).records["press"].has_torque


@pytest.mark.slow
def test_mpm_smoke_twist(tmp_path: Path) -> None:
    """Tiny CPU MPM bed: the twist runs end to end with a torque every frame (not a physics check beyond its sign)."""
    from gmloco.eval.calibration.build import smoke_build_cfg

    cfg = replace(smoke_build_cfg("dry_sand", str(tmp_path)), experiments=("twist",))
    rec = load_dataset(build_dataset(cfg)[0]).records["twist"]
    assert rec.has_torque and np.all(np.isfinite(rec.torque))
    first_turn = rec.phase == YAW_PHASES[0]
    assert first_turn.any() and float(np.mean(rec.torque[first_turn, 2])) < 0.0  # turning +z, the sand resists
