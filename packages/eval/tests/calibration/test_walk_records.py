# SPDX-License-Identifier: Apache-2.0
"""MPM walk recordings as sole records, and the models' replay of them, on a committed MPM recording."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from gmloco.contact import RftExtensionsCfg
from gmloco.eval.calibration.dataset import load_dataset, save_dataset
from gmloco.eval.calibration.fit import SandFitCfg
from gmloco.eval.calibration.walk_records import WALK_FRAME_DT, WalkRecordsCfg, foot_records, walk_dataset
from gmloco.eval.calibration.walk_records import main as records_main
from gmloco.eval.calibration.walk_replay import binned_forces, walk_replay
from gmloco.eval.calibration.walk_replay import main as replay_main

RUNS = Path(__file__).resolve().parents[4] / "results/mpm_eval/table_rows/dry_sand_square_window/runs"
WALK = RUNS / "table_td_dry_sand_sq_share0of4/recordings/dry_sand__straight__v1.mcap"
"""The td student's first 1.0 m/s walk on MPM dry sand (3 cm voxels): 309 frames, the pelvis below 0.5 m from 304."""
pytestmark = [
    pytest.mark.filterwarnings("ignore::UserWarning"),
    pytest.mark.skipif(not WALK.is_file(), reason="committed MPM recording not in this checkout"),
]


@pytest.fixture(scope="module")
def records() -> dict:
    """Both feet of the walk."""
    return foot_records(WALK)


def test_kinematics_reproduce_the_recorded_sinkage(records: dict) -> None:
    """Forward kinematics of the logged pose puts the soles where Newton had them (the recorded sinkage, to 1 mm).

    ``foot_records`` refuses a file beyond the tolerance; here its records are checked against the log directly.
    """
    from gmloco.deploy.logs.reader import read_log

    _, sinkage = read_log(WALK).signal("sim.sinkage")
    left, right = records["left"], records["right"]
    n = len(left.time)
    assert n == 304 and len(sinkage) == 309 and np.allclose(np.diff(left.time), WALK_FRAME_DT)
    np.testing.assert_allclose(np.stack([left.depth, right.depth], axis=1), sinkage[:n], atol=1e-3)
    assert left.rot.shape == (n, 3, 3) and np.allclose(left.rot @ left.rot.transpose(0, 2, 1), np.eye(3), atol=1e-9)


def test_sole_velocity_is_the_derivative_of_its_position(records: dict) -> None:
    """The sole centre's velocity is d/dt of its forward-kinematics position along the logged generalized velocity.

    Each sampled frame's pose is integrated for 1 ms along (pelvis velocity in world axes, body angular velocity,
    joint rates) with MuJoCo and the sole centre moved by lin_vel * 1 ms (the 50 Hz samples are too coarse for a
    finite difference of the recorded positions: the joint rates change within a frame).
    """
    import mujoco

    from gmloco.deploy.logs.reader import read_log
    from gmloco.deploy.mismatch.frames import quat_rotate
    from gmloco.deploy.mismatch.g1model import build_model

    log = read_log(WALK)
    sig = {s: log.signal(s)[1] for s in ("odom.position", "odom.orientation", "odom.linear_velocity",
                                         "odom.angular_velocity", "lowstate.q", "lowstate.dq")}  # fmt: skip
    model = build_model()
    data = mujoco.MjData(model)
    body = model.body("left_ankle_roll_link").id
    centre = np.asarray(WalkRecordsCfg().sole_center)
    h, rec = 1e-3, records["left"]
    for k in range(0, 300, 37):
        qpos = np.concatenate([sig["odom.position"][k], sig["odom.orientation"][k], sig["lowstate.q"][k]])
        v = quat_rotate(sig["odom.orientation"][k : k + 1], sig["odom.linear_velocity"][k : k + 1])[0]
        qvel = np.concatenate([v, sig["odom.angular_velocity"][k], sig["lowstate.dq"][k]])
        mujoco.mj_integratePos(model, qpos, qvel, h)
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        moved = data.xpos[body] + data.xmat[body].reshape(3, 3) @ centre
        assert np.linalg.norm((moved - rec.pos[k]) / h - rec.lin_vel[k]) < 0.01 + 0.01 * np.linalg.norm(rec.lin_vel[k])


def test_dataset_splits_by_walk_and_round_trips(tmp_path: Path, records: dict) -> None:
    """Both feet of a walk share a split; the file reads back with the walk protocol (50 Hz, the MPM sole box)."""
    second = tmp_path / "study" / "runs" / "run_b" / "recordings" / WALK.name
    second.parent.mkdir(parents=True)
    shutil.copy(WALK, second)
    ds = walk_dataset([WALK, second], "dry_sand")
    assert len(ds.records) == 4 and sorted(set(ds.split.values())) == ["fit", "heldout"]
    for name, split in ds.split.items():
        assert ds.split[name.rsplit("__", 1)[0] + "__left"] == split
    back = load_dataset(save_dataset(ds, tmp_path / "walks.npz"))
    assert back.protocol.frame_dt == WALK_FRAME_DT and back.extra and back.extra["kind"] == "walks"
    np.testing.assert_allclose(back.protocol.sole_size, 2.0 * np.asarray(WalkRecordsCfg().sole_half_extents))


def test_bad_walks_exit_2(tmp_path: Path) -> None:
    """A missing file, another material's bed, a rough bed and a walk cut short by a fall exit 2 with the reason."""
    rough = tmp_path / "dry_sand_rough__straight__v1.mcap"
    shutil.copy(WALK, rough)
    out = str(tmp_path / "w.npz")
    assert records_main(["--recordings", str(tmp_path / "none.mcap"), "--material", "dry_sand", "--out", out]) == 2
    assert records_main(["--recordings", str(WALK), "--material", "basalt", "--out", out]) == 2
    assert records_main(["--recordings", str(rough), "--material", "dry_sand", "--out", out]) == 2
    with pytest.raises(ValueError, match="frames before the pelvis"):
        foot_records(WALK, WalkRecordsCfg(min_pelvis_height=2.0))
    assert not Path(out).exists()


def test_binned_forces_hand_values() -> None:
    """Frames fall into their speed and depth bins; shallow frames are left out; means per source."""
    depth = np.array([0.001, 0.01, 0.01, 0.05, 0.10])
    speed = np.array([0.0, 0.1, 0.1, 0.3, 2.0])
    mpm = np.array([[0, 0, 9], [3, 4, 10], [0, 0, 20], [0, 1, 30], [6, 8, 40]], dtype=float)
    rows = binned_forces(depth, speed, {"mpm": mpm, "model": 2.0 * mpm})
    assert [(r["speed_mps"], r["depth_m"], r["n"]) for r in rows] == [
        ([0.0, 0.2], [0.005, 0.03], 2),
        ([0.2, 0.5], [0.03, 0.06], 1),
        ([1.0, None], [0.06, 0.30], 1),
    ]
    assert rows[0]["mpm"] == {"fz": 15.0, "fxy": 2.5} and rows[0]["model"] == {"fz": 30.0, "fxy": 5.0}


def test_walk_replay_summary_and_bad_input(tmp_path: Path) -> None:
    """The published model is always replayed; a rate drag changes only the horizontal forces; bad input exits 2."""
    ds = walk_dataset([WALK], "dry_sand")
    summary = walk_replay(ds, {"drag": RftExtensionsCfg(rate_drag=3.0)}, SandFitCfg())
    assert list(summary["rms_force_error_N"]) == ["published", "drag"]
    assert summary["dataset"]["frames"] == 608 and sum(r["n"] for r in summary["bins"]) > 300
    fast = [r for r in summary["bins"] if r["speed_mps"][0] >= 0.5]
    assert all(r["drag"]["fz"] == pytest.approx(r["published"]["fz"]) for r in fast)
    assert sum(r["drag"]["fxy"] for r in fast) > sum(r["published"]["fxy"] for r in fast)
    path = save_dataset(ds, tmp_path / "walks.npz")
    ext = tmp_path / "ext.json"
    ext.write_text(json.dumps({"extensions": {"rate_drag": 3.0}}))
    assert replay_main(["--dataset", str(path), "--model", f"drag={ext}", "--out", str(tmp_path / "o")]) == 0
    assert (tmp_path / "o" / "fig_walk_forces.png").stat().st_size > 1000
    for bad in ([f"drag{ext}"], [f"published={ext}"], [f"drag={tmp_path / 'none.json'}"]):
        assert replay_main(["--dataset", str(path), "--model", *bad, "--out", str(tmp_path / "x")]) == 2
    assert replay_main(["--dataset", str(tmp_path / "none.npz"), "--out", str(tmp_path / "x")]) == 2
    assert not (tmp_path / "x").exists()
