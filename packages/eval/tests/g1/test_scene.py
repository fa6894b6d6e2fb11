# SPDX-License-Identifier: Apache-2.0
"""G1 on a tiny coupled MPM bed (CPU smoke): the sand carries the robot, driven by an exported ONNX policy."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gmloco.eval.g1.policy import MjlabOnnxPolicy
from gmloco.eval.g1.scene import G1MpmScene
from gmloco.eval.g1.scene_cfg import G1MpmSceneCfg
from gmloco.eval.g1.soles import needs_sand, sole_reach, soles_outside
from gmloco.eval.mpm.box_scene import MpmSolverCfg, frame_dt_problem
from gmloco.eval.mpm.window import SandWindowCfg

POLICY = Path(__file__).resolve().parents[4] / "artifacts" / "ppo_rft3d" / "policy.onnx"


@pytest.fixture(scope="module")
def standing_g1() -> G1MpmScene:
    """0.2 s (20 frames of 100 Hz MPM, 200 Hz physics, 50 Hz policy) on a 0.6 x 0.5 x 0.15 m bed, 5 cm voxels."""
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    scene = G1MpmScene(G1MpmSceneCfg(solver=MpmSolverCfg(voxel_size=0.05, frame_dt=0.01, rigid_substeps=2)),
                       MjlabOnnxPolicy(POLICY))  # fmt: skip
    scene.run(20)
    return scene


def test_soles_outside_counts_low_corners_beyond_the_window() -> None:
    """Window x in [0, 1], y in [-0.5, 0.5]: corners behind it count if within 2 cm of the sand, not if higher."""
    bounds = (np.array([[0.5, 0.0]]), np.zeros(1), np.array([0.5, 0.5]))  # centre, heading, half extents
    corners = np.zeros((1, 2, 8, 3))
    corners[0, 0, :, 0] = 0.5  # left sole inside
    corners[0, 1, :, 0] = np.linspace(-0.21, 0.14, 8)  # right sole straddles the rear edge: 5 corners behind it
    surface = np.zeros((1, 2, 8))
    assert soles_outside(corners, needs_sand(corners, surface), bounds).tolist() == [5]
    corners[0, 1, :, 2] = 0.05  # the right sole 5 cm up in its swing: no sand needed
    assert soles_outside(corners, needs_sand(corners, surface), bounds).tolist() == [0]
    corners[0, 1, :, 2], corners[0, 1, :, 0], corners[0, 1, :, 1] = -0.03, 0.5, 0.6  # sunk, beside the window
    assert soles_outside(corners, needs_sand(corners, surface), bounds).tolist() == [8]
    # the window turned by 45 degrees about its centre reaches y = 0.707 at x = 0.5: the sunk sole is inside it
    turned = (bounds[0], np.array([np.pi / 4]), bounds[2])
    assert soles_outside(corners, needs_sand(corners, surface), turned).tolist() == [0]


def test_sole_reach_is_measured_in_the_pelvis_yaw_frame() -> None:
    """Pelvis at (1, 2) facing +y: a corner at y = 2.5 is 0.5 m ahead, one at x = 0.7 is 0.3 m to the side."""
    yaw90 = [0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)]  # x y z w
    base_q = np.array([[1.0, 2.0, 0.7, *yaw90], [1.0, 2.0, 0.7, *yaw90]])
    corners = np.zeros((2, 2, 8, 3))
    corners[..., 0], corners[..., 1] = 1.0, 2.0
    corners[0, 0, 0, 1], corners[0, 0, 1, 1], corners[0, 1, 2, 0] = 2.5, 1.8, 0.7
    corners[1, ..., 2] = 0.1  # robot 1: both soles 10 cm up
    reach = sole_reach(corners, needs_sand(corners, np.zeros((2, 2, 8))), base_q)
    np.testing.assert_allclose(reach[0], [0.2, 0.5, 0.3], atol=1e-12)
    assert np.isnan(reach[1]).all()
    corners[..., 2] = 0.1  # every sole in the air
    assert np.isnan(sole_reach(corners, needs_sand(corners, np.zeros((2, 2, 8))), base_q)).all()


def test_policy_metadata_layout() -> None:
    """The mjlab export's metadata: 29 joints, 6 terms x 5 frames = 480 inputs, gains and q_0 in action order."""
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    pol = MjlabOnnxPolicy(POLICY)
    assert pol.obs_dim == 480 and len(pol.spec.joint_names) == 29
    assert pol.spec.joint_names[0] == "left_hip_pitch_joint" and np.isclose(pol.spec.default_joint_pos[3], 0.669)
    a = pol.act({n: np.zeros(d) for n, d in zip(pol.term_names, pol.term_dims, strict=True)})
    assert a.shape == (1, 29) and np.all(np.isfinite(a))
    # batched: three robots with the same history act exactly like one
    pol3 = MjlabOnnxPolicy(POLICY, num_robots=3)
    terms = {n: np.full((3, d), 0.1) for n, d in zip(pol3.term_names, pol3.term_dims, strict=True)}
    a3 = pol3.act(terms)
    a1 = MjlabOnnxPolicy(POLICY).act({n: v[:1] for n, v in terms.items()})
    np.testing.assert_allclose(a3, np.repeat(a1, 3, axis=0), rtol=1e-5, atol=1e-6)


def test_sand_supports_g1(standing_g1: G1MpmScene) -> None:
    """Over the second half of the run, the sand force on the feet is m g within 50 %; state finite, sinkage small."""
    scene = standing_g1
    scene.test_final()
    ratio = scene.support_ratio(skip=0.5)[0]
    assert 0.5 < ratio < 1.5, f"sand force / weight = {ratio:.2f}"
    sinkage = np.asarray(scene.sinkage)
    assert np.all(np.isfinite(sinkage)) and sinkage.max() < 0.1, f"max sinkage {sinkage.max():.3f} m"
    assert np.all(np.isfinite(np.asarray(scene.foot_force)))
    assert scene.base_q[-1][0, 2] > 0.6, "pelvis dropped"


def _standing(moving: bool, num_robots: int = 1) -> G1MpmScene:
    """PD-only G1(s) in the default pose on a 0.9 x 0.6 m window; a moving one is pushed 0.1 m ahead at 0.1 s."""
    spec = MjlabOnnxPolicy(POLICY).spec
    cfg = G1MpmSceneCfg(window=SandWindowCfg(moving=moving, length=0.9, width=0.6, lead=0.0), num_robots=num_robots,
                        solver=MpmSolverCfg(voxel_size=0.05, frame_dt=0.01, rigid_substeps=2))  # fmt: skip
    scene = G1MpmScene(cfg, spec)
    scene.run(10)
    scene.window.arrays.lead = 0.1  # the window moves 4 columns: its rear columns are recycled in front
    scene.run(16)
    return scene


def test_moving_window_keeps_standing_sinkage() -> None:
    """A window recycling columns while two robots stand: each one's sinkage as on a static bed.

    Tolerance: a quarter of the particle spacing h = 2.5 cm (sinkage is read on a particle bed, so differences
    below h / 4 are below its resolution); the pelvis height within the same tolerance.
    """
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    static, moving = _standing(False), _standing(True, num_robots=2)
    assert not np.asarray(moving.sole_out).any() and not np.asarray(static.sole_out).any()  # soles over sand
    behind, ahead, side = np.nanmax(np.asarray(static.sole_reach)[:, 0], axis=0)  # standing: heel, toe, outer edge
    assert 0.02 < behind < 0.1 and 0.1 < ahead < 0.17 and 0.08 < side < 0.2, (behind, ahead, side)
    lo_x = moving.window.bounds()[:, 0, 0]
    np.testing.assert_allclose(lo_x, [-0.35, -0.35], atol=1e-6)  # the window did move (was -0.45)
    s_static, s_moving = np.asarray(static.sinkage)[:, 0], np.asarray(moving.sinkage)
    assert s_static[-1] > 0.01, "the robot should have sunk into the sand"
    # robot 0 stands on the same grains as the static bed's robot; robot 1 on another jitter realization
    for r in range(2):
        np.testing.assert_allclose(s_moving[:, r], s_static, atol=0.25 * moving.window.h)
        z_moving, z_static = np.asarray(moving.base_q)[:, r, 2], np.asarray(static.base_q)[:, 0, 2]
        np.testing.assert_allclose(z_moving, z_static, atol=0.25 * moving.window.h)


@pytest.mark.slow
def test_robots_as_worlds_match_one_mujoco_world() -> None:
    """The CUDA layout (one mujoco_warp world per robot), run on CPU, follows MuJoCo C with both robots in one world.

    Reference: mujoco_warp matches MuJoCo C to ~1e-7 in qpos on the G1 (``stack.md``). Over 16 coupled frames with
    the walking policy the pelvis positions stay within 1e-4 m. Measured: 2.6e-5 m with the window walls as MPM
    colliders, 1.2e-7 m with the particle clamp only. The difference jumps in one policy step (1.6e-8 -> 8.9e-6 m
    at step 5), a discrete event in the sand rather than drift; the cause is not isolated (a plausible one: the
    unconverged 50-iteration Gauss-Seidel solve depends on the sparse grid's active cells).
    """
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    policy = MjlabOnnxPolicy(POLICY, num_robots=2)
    q = {}
    for worlds in (False, True):
        policy.reset()
        cfg = G1MpmSceneCfg(num_robots=2, robots_as_worlds=worlds, commands=((1.0, 0.0, 0.0), (2.0, 0.0, 0.0)),
                            window=SandWindowCfg(moving=True, length=0.8, width=0.5),
                            solver=MpmSolverCfg(voxel_size=0.05, frame_dt=0.01, rigid_substeps=2,
                                                max_active_cell_count=2000))  # fmt: skip
        scene = G1MpmScene(cfg, policy)
        scene.run(16)
        scene.mpm.check_sparse_grid_rebuild_status()
        q[worlds] = np.asarray(scene.base_q)
    np.testing.assert_allclose(q[True][:, :, :3], q[False][:, :, :3], atol=1e-4)


def _stiff_standing(
    depth: float, frames: int, gain: float = 10.0, drop_height: float = 0.005, floor_contact: bool = True
) -> G1MpmScene:
    """A G1 holding the default pose with PD gains ``gain`` x the policy's, on dry sand ``depth`` deep, 5 cm voxels.

    mjlab's gains alone let the PD-only default pose fold (knees +0.16 rad in 0.2 s) and tip over backwards even on
    rigid ground, so its sinkage would measure the posture; 10x stiffer joints stand still on rigid ground (pelvis
    within 7 mm of the default pose over 1 s) and load the sand like a rigid G1 (``results/mpm_eval/G1_SINKAGE.md``).
    """
    from dataclasses import replace

    from gmloco.eval.mpm.window_terrain import terrain_cfg

    spec = MjlabOnnxPolicy(POLICY).spec
    spec = replace(spec, kp=spec.kp * gain, kd=spec.kd * gain)
    cfg = G1MpmSceneCfg(terrain=terrain_cfg("dry_sand", depth=depth),
                        window=SandWindowCfg(moving=False, length=0.6, width=0.5, lead=0.0),
                        solver=MpmSolverCfg(voxel_size=0.05, frame_dt=0.01, rigid_substeps=2),
                        drop_height=drop_height, floor_contact=floor_contact)  # fmt: skip
    scene = G1MpmScene(cfg, spec)
    scene.run(frames)
    return scene


def test_standing_g1_is_carried_by_sand() -> None:
    """A standing G1 on 15 cm of dry sand (5 cm voxels) for 1 s: the sand, not the floor, carries it.

    Measured (CPU): lowest sole corner 3.0 / 3.6 cm deep at 0.4 / 0.6 s (the quasi-static 10 cm footing of the
    same sand carries a G1 foot within 1-3.5 cm), then the stiff statue tips back onto its heels (8.5 cm at 1 s,
    pelvis 0.672 m); sand force over the last half 0.99 m g. Before the window walls were MPM colliders the same
    robot sank ~20 cm in 0.4 s on 30 cm of sand (pelvis 0.52 m).
    """
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    scene = _stiff_standing(depth=0.15, frames=100)
    scene.test_final()
    sink, z = np.asarray(scene.sinkage)[:, 0], np.asarray(scene.base_q)[:, 0, 2]  # 50 Hz samples
    assert sink[25] < 0.045, f"lowest sole corner {sink[25]:.3f} m deep at 0.5 s"
    assert sink.max() < 0.8 * scene.cfg.terrain.depth, f"a sole neared the floor: {sink.max():.3f} m"
    assert z[-10:].min() > 0.62, f"pelvis down to {z[-10:].min():.3f} m in the last 0.2 s"
    ratio = scene.support_ratio(skip=0.5)[0]
    assert 0.8 < ratio < 1.2, f"sand force / weight = {ratio:.2f}"


def test_soles_stand_on_the_floor_under_a_shallow_bed() -> None:
    """A G1 dropped from 0.3 m onto 5 cm of sand punches through to the rigid floor, and the floor stops its soles.

    Measured (CPU): with the floor contact the lowest sole corner peaks 8 mm into the floor at the 2.4 m/s impact
    (MuJoCo's soft contact) and rests 1 mm into it; without it the soles are 20 cm under the floor 0.1 s later.
    """
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    depth = 0.05
    scene = _stiff_standing(depth=depth, frames=40, drop_height=0.3)
    scene.test_final()
    sink = np.asarray(scene.sinkage)[:, 0]
    assert sink.max() < depth + 0.012, f"a sole passed the floor: {sink.max():.3f} m below the surface"
    assert abs(sink[-1] - depth) < 0.005, f"the soles should rest on the floor: {sink[-1]:.3f} m"
    assert np.asarray(scene.base_q)[-1, 0, 2] > 0.65
    without = np.asarray(_stiff_standing(depth=depth, frames=40, drop_height=0.3, floor_contact=False).sinkage)[:, 0]
    assert without.max() > depth + 0.05, "without the floor contact the soles should pass the floor (control)"


def test_odd_substeps_keep_the_frame_buffers_and_the_physics(monkeypatch: pytest.MonkeyPatch) -> None:
    """5 ms frames x 1 rigid step: frames end on the State objects they start with, the pelvis path unchanged.

    A captured CUDA graph replays fixed buffers; without the parity copy an odd substep count swaps them every frame.
    The copy moves values and changes none: the walk is identical with and without it.
    """
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")

    def walk(parity: bool) -> tuple[np.ndarray, np.ndarray, bool]:
        if not parity:
            monkeypatch.setattr(G1MpmScene, "_restore_state_parity", lambda self: None)
        cfg = G1MpmSceneCfg(commands=((1.0, 0.0, 0.0),), window=SandWindowCfg(moving=True, length=0.6, width=0.5),
                            solver=MpmSolverCfg(voxel_size=0.05, frame_dt=0.005, rigid_substeps=1))  # fmt: skip
        scene = G1MpmScene(cfg, MjlabOnnxPolicy(POLICY))
        first = scene.state_0
        scene.run(7)  # an odd frame count: without the copy the buffers end swapped
        return np.asarray(scene.base_q), scene.state_0.joint_q.numpy(), scene.state_0 is first

    base_parity, joints_parity, same_buffers = walk(parity=True)
    base_plain, joints_plain, swapped_back = walk(parity=False)
    assert same_buffers and not swapped_back
    np.testing.assert_array_equal(base_parity, base_plain)
    np.testing.assert_array_equal(joints_parity, joints_plain)
    assert np.ptp(base_parity[:, 0, 2]) > 0.0  # the pelvis moved: the comparison is not between two resting robots


@pytest.mark.parametrize(
    ("frame_dt", "ok"), [(0.01, True), (0.005, True), (0.0025, True), (0.003, False), (0.04, False)]
)
def test_frame_dt_must_divide_the_policy_step(frame_dt: float, ok: bool) -> None:
    """Whole frames per 50 Hz policy step, else a reason naming the value; the scene refuses such a frame."""
    problem = frame_dt_problem(frame_dt)
    assert (problem is None) == ok
    if not ok:
        assert str(frame_dt) in str(problem)
        if POLICY.exists():
            with pytest.raises(ValueError, match="must divide"):
                G1MpmScene(G1MpmSceneCfg(solver=MpmSolverCfg(frame_dt=frame_dt)), MjlabOnnxPolicy(POLICY))


def _pd_scene(cfg: G1MpmSceneCfg) -> G1MpmScene:
    """A scene of PD-only G1s (the exported policy's gains and default pose, no policy acting); skipped without it."""
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    return G1MpmScene(cfg, MjlabOnnxPolicy(POLICY).spec)


def test_reset_robot_restarts_its_lane_on_fresh_sand() -> None:
    """Robot 1 of two standing robots reset after 10 frames: a fresh start on fresh sand, robot 0 untouched.

    Start pose at rest, new command, new stress-free grains (another jitter) in its window; robot 0 and its sand
    keep their state; its new stand sinks as its first one did (within a quarter of the particle spacing).
    """
    cfg = G1MpmSceneCfg(window=SandWindowCfg(moving=True, length=0.9, width=0.6, lead=0.0), num_robots=2,
                        solver=MpmSolverCfg(voxel_size=0.05, frame_dt=0.01, rigid_substeps=2))  # fmt: skip
    scene = _pd_scene(cfg)
    q_start = scene.state_0.joint_q.numpy().copy()
    scene.run(10)
    nq, nd, p = scene.coords_per_robot, scene.dofs_per_robot, scene.window.particles_per_robot
    q_before, x_before = scene.state_0.joint_q.numpy().copy(), scene.sand_state.particle_q.numpy().copy()
    assert not np.allclose(q_before[nq:], q_start[nq:])  # it has settled into the sand
    scene.reset_robots([1], [(0.5, 0.0, 0.0)], [7])
    q = scene.state_0.joint_q.numpy()
    np.testing.assert_allclose(q[nq:], q_start[nq:], atol=1e-6)
    np.testing.assert_array_equal(q[:nq], q_before[:nq])
    assert not scene.state_0.joint_qd.numpy()[nd:].any() and tuple(scene.commands[1]) == (0.5, 0.0, 0.0)
    x = scene.sand_state.particle_q.numpy()
    np.testing.assert_array_equal(x[:p], x_before[:p])
    assert np.abs(x[p:] - x_before[p:]).max() > 0.1 * scene.window.h  # new grains
    assert not scene.sand_state.mpm.particle_stress.numpy()[p:].any()
    scene.run(10)
    z = np.asarray(scene.sinkage)[:, 1]
    np.testing.assert_allclose(z[5:], z[:5], atol=0.25 * scene.window.h)  # policy steps 0-4 again after the reset


def test_a_retired_robot_loses_its_sand_and_the_other_walks_on_unchanged() -> None:
    """Two standing robots; after 6 frames robot 1 is retired: no sand force on it, robot 0 as without the retire.

    Its lane's sand leaves the MPM solve (``retire_robots``), so the sand pushes on its soles no more (hundreds of
    newtons before, ~1e-3 N after); robot 0 moves as in a run where robot 1 kept its sand (lanes share no grid
    cell), to 1e-5 m over 6 more frames.
    """
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    spec = MjlabOnnxPolicy(POLICY).spec
    cfg = G1MpmSceneCfg(window=SandWindowCfg(moving=True, length=0.9, width=0.6, lead=0.0), num_robots=2,
                        solver=MpmSolverCfg(voxel_size=0.05, frame_dt=0.01, rigid_substeps=2))  # fmt: skip
    pelvis, wrench = [], []
    for retire in (False, True):
        scene = G1MpmScene(cfg, spec)
        scene.run(6)
        if retire:
            scene.retire_robots([1])
        scene.run(6)
        pelvis.append(scene.state_0.body_q.numpy()[:: scene.bodies_per_robot].copy())
        wrench.append(scene.sand_wrench.numpy().reshape(2, scene.bodies_per_robot, 6).copy())
    np.testing.assert_allclose(pelvis[1][0], pelvis[0][0], atol=1e-5)
    assert np.abs(wrench[0][1]).max() > 1.0  # kept: the sand carries robot 1
    assert np.abs(wrench[1][1]).max() < 1e-2  # retired: no sand force on robot 1 (1e-3 N of collider round-off)
    np.testing.assert_allclose(wrench[1][0], wrench[0][0], rtol=1e-3, atol=1e-3)


def test_policy_reset_of_one_robot_back_fills_its_history_only() -> None:
    """After ``reset([1])`` robot 1's history holds its next frame in every slot; robot 0's keeps shifting."""
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    pol = MjlabOnnxPolicy(POLICY, num_robots=2)
    dims = dict(zip(pol.term_names, pol.term_dims, strict=True))
    frame = lambda v: {n: np.full((2, d), v) for n, d in dims.items()}  # noqa: E731
    pol.act(frame(1.0))
    pol.act(frame(2.0))
    pol.reset([1])
    pol.act(frame(3.0))
    assert pol._hist is not None
    for h, s in zip(pol._hist, pol.term_scale, strict=True):
        np.testing.assert_allclose(h[1], 3.0 * s)  # back-filled with the new frame
        np.testing.assert_allclose(h[0, -3:], np.array([[1.0], [2.0], [3.0]]) * s * np.ones_like(h[0, -3:]))


def test_foot_force_is_the_mean_over_the_policy_step(monkeypatch: pytest.MonkeyPatch) -> None:
    """The logged foot force is the mean of the frames' applied sand wrench since the previous policy step.

    5 ms frames (4 per 50 Hz policy step, the tables' setting), with the two-frame mean on (``wrench_frames=2``):
    each frame's applied and raw wrench on the feet are recorded after the frame; the applied one is the mean of
    this frame's raw wrench and the last one's, and every logged sample after the first is the mean of the 4
    applied frames before it. A value other than 1 or 2 is refused.
    """
    cfg = G1MpmSceneCfg(window=SandWindowCfg(moving=False, length=0.6, width=0.5, lead=0.0), wrench_frames=2,
                        solver=MpmSolverCfg(voxel_size=0.05, frame_dt=0.005, rigid_substeps=1))  # fmt: skip
    scene = _pd_scene(cfg)
    applied: list[np.ndarray] = []
    raw: list[np.ndarray] = []
    simulate = scene.simulate

    def recorded() -> None:
        simulate()
        for out, array in ((applied, scene.sand_wrench), (raw, scene.sand_wrench_raw)):
            out.append(array.numpy()[scene.foot_bodies][..., :3].astype(np.float64))

    monkeypatch.setattr(scene, "simulate", recorded)
    scene.run(12)
    per_frame, per_raw = np.stack(applied), np.stack(raw)  # [12, R, 2, 3]
    np.testing.assert_allclose(per_frame[1:], 0.5 * (per_raw[1:] + per_raw[:-1]), rtol=1e-5, atol=1e-3)
    logged = np.asarray(scene.foot_force)  # samples at frames 0, 4, 8
    assert scene.frames_per_policy == 4 and len(logged) == 3
    for k in (1, 2):
        np.testing.assert_allclose(logged[k], per_frame[4 * (k - 1) : 4 * k].mean(axis=0), rtol=1e-5, atol=1e-3)
    assert np.abs(per_frame).max() > 1.0  # the sand carries the soles: the means compare real forces
    with pytest.raises(ValueError, match="wrench_frames=3"):
        G1MpmScene(G1MpmSceneCfg(wrench_frames=3), scene.spec)
