# SPDX-License-Identifier: Apache-2.0
"""The moving sand window: column recycling bookkeeping, the MPM solver's cached volumes, terrain filling."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.coupled_setup import make_mpm_solver
from gmloco.eval.mpm.window import SandWindow, SandWindowCfg
from gmloco.eval.mpm.window_terrain import MpmTerrainCfg, terrain_cfg, terrain_layer, terrain_surface_height

VOXEL = 0.1  # columns h = 5 cm at 2 particles per voxel edge


def _pelvis(x: np.ndarray, lane_y: np.ndarray, bodies: int, heading: float | np.ndarray = 0.0) -> np.ndarray:
    """Body poses [R bodies, 7] with each robot's pelvis at (x_r, lane_y_r, 0.7), yawed by ``heading`` [rad]."""
    q = np.zeros((len(x) * bodies, 7), dtype=np.float32)
    yaw = np.repeat(np.broadcast_to(heading, len(x)), bodies)
    q[:, 5], q[:, 6] = np.sin(0.5 * yaw), np.cos(0.5 * yaw)  # x y z w
    q[::bodies, 0], q[::bodies, 1], q[::bodies, 2] = x, lane_y, 0.7
    return q


def _window(
    terrain: MpmTerrainCfg,
    lane_y: np.ndarray,
    bodies: int = 2,
    capacity: int = -1,
    turn: bool = False,
    heading: float = 0.0,
) -> tuple[SandWindow, Any, Any, Any]:
    """A 2-robot window (0.5 x 0.3 m, 5 cm columns), seeded at x = 0, with its sand model, state and solver.

    ``capacity`` > 0: the evaluation's rebuildable sparse grid of that many cells (else one allocated per step);
    ``turn``: the window turns with the robots (else it keeps the grid's axes), seeded at ``heading`` [rad].
    """
    import newton
    import warp as wp

    cfg = SandWindowCfg(moving=True, length=0.5, width=0.3, lead=0.0, turn_with_robot=turn)
    win = SandWindow(cfg, terrain, VOXEL, lane_y, bodies)
    builder = newton.ModelBuilder()
    newton.solvers.SolverImplicitMPM.register_custom_attributes(builder)
    win.add_particles(builder)
    model = builder.finalize(device="cpu")
    win.allocate(wp, model.device)
    body_q = wp.array(_pelvis(np.zeros(len(lane_y)), lane_y, bodies, heading), dtype=wp.transform, device="cpu")
    win.seed_model(wp, model, body_q)
    solver = make_mpm_solver(newton, model, MpmSolverCfg(voxel_size=VOXEL, max_active_cell_count=capacity),
                             win.materials[0])  # fmt: skip
    state = model.state()
    win.bind(model, state, solver)
    return win, model, state, solver


def test_recycle_moves_exactly_the_columns_left_behind() -> None:
    """Advance robot 0 by 2.4 columns: 2 columns x ny x nz particles re-seeded ahead, the rest untouched, mass kept."""
    import warp as wp

    lane_y = np.array([0.0, 2.0])
    win, model, state, _ = _window(terrain_cfg("dry_sand"), lane_y)
    h, per = win.h, win.particles_per_robot
    assert (win.nx, win.ny, win.nz) == (10, 6, 3) and np.isclose(h, 0.05)
    q0, m0 = state.particle_q.numpy().copy(), model.particle_mass.numpy().sum()
    # fill: 5 cm cubes, rho_c 1500 kg/m^3 -> 0.1875 kg each; bed 0.5 x 0.3 x 0.15 m per robot
    np.testing.assert_allclose(model.particle_mass.numpy(), 1500.0 * 0.05**3, rtol=1e-6)
    win.advance(wp.array(_pelvis(np.array([2.4 * h, 0.0]), lane_y, 2), dtype=wp.transform, device="cpu"))
    q1 = state.particle_q.numpy()
    moved = np.any(q1 != q0, axis=1)
    assert moved[:per].sum() == 2 * win.ny * win.nz and not moved[per:].any()
    # window [-0.25, 0.25) m (origin column -5) -> [-0.15, 0.35) m (origin -3): world columns -5 and -4 left,
    # columns 5 and 6 (x in [0.25, 0.35) m) entered
    x_new = q1[:per][moved[:per], 0]
    np.testing.assert_array_equal(np.unique(np.floor(x_new / h + 1e-6)), [5.0, 6.0])
    np.testing.assert_array_equal(np.unique(np.floor(q0[:per][moved[:per], 0] / h + 1e-6)), [-5.0, -4.0])
    np.testing.assert_allclose(model.particle_mass.numpy().sum(), m0, rtol=1e-6)
    lo, hi = win.bounds()[0]
    np.testing.assert_allclose([lo[0], hi[0]], [-0.15, 0.35], atol=1e-6)


def test_recycle_keeps_the_mpm_volume_cache_consistent() -> None:
    """Rough transition sand: after a recycle the solver's cached volume/density equal a fresh notify's."""
    import warp as wp

    terrain = MpmTerrainCfg(name="t", materials=("basalt", "poppy_seed"), layer_start=0.0, layer_length=0.3,
                         rough_amplitude=0.03, rough_wavelength=0.4)  # fmt: skip
    lane_y = np.array([0.0, 2.0])
    win, model, state, solver = _window(terrain, lane_y)
    win.advance(wp.array(_pelvis(np.array([0.33, -0.21]), lane_y, 2), dtype=wp.transform, device="cpu"))
    mm = solver._mpm_model
    cached = [a.numpy().copy() for a in (mm.particle_volume, mm.particle_density, mm.material_particle_volume)]
    mm.notify_particle_material_changed()
    fresh = [a.numpy() for a in (mm.particle_volume, mm.particle_density, mm.material_particle_volume)]
    for c, f in zip(cached, fresh, strict=True):
        np.testing.assert_allclose(c, f, rtol=1e-5)
    # every particle carries its medium: density and friction of the layer at its column centre
    q = state.particle_q.numpy()
    col_x = (win.column.numpy()[:, 0] + 0.5) * win.h
    layer = terrain_layer(terrain, col_x)
    dens = np.array([m.density for m in win.materials])[layer]
    np.testing.assert_allclose(fresh[1], dens, rtol=1e-5)
    np.testing.assert_allclose(model.mpm.friction.numpy(), np.array([m.friction for m in win.materials])[layer],
                               rtol=1e-6)  # fmt: skip
    # columns fill floor -> surface: the column's particle volumes add up to h^2 (z_s + depth) at its jittered
    # centre, within the surface's variation over half a column (|grad z_s| h / 2 <= A k h / 2)
    cols = win.column.numpy()
    r = np.arange(len(q)) // win.particles_per_robot
    key = (cols[:, 0] * 100_003 + cols[:, 1]) * 7 + r
    _, inv = np.unique(key, return_inverse=True)
    vol = np.bincount(inv, weights=fresh[0])
    first = np.unique(inv, return_index=True)[1]
    xs, ys = q[first, 0], q[first, 1] - lane_y[r[first]]
    expect = win.h**2 * (terrain_surface_height(terrain, xs, ys) + terrain.depth)
    k = 2 * np.pi / terrain.rough_wavelength
    np.testing.assert_allclose(vol, expect, atol=win.h**2 * terrain.rough_amplitude * k * win.h)


def test_walls_keep_sand_in_the_window() -> None:
    """A particle pushed out of its window is put back on the wall with no outward velocity."""
    import warp as wp

    lane_y = np.array([0.0, 2.0])
    win, _, state, _ = _window(terrain_cfg("poppy_seed"), lane_y)
    q, v = state.particle_q.numpy(), state.particle_qd.numpy()
    q[0, 0], v[0, 0] = -1.0, -0.5
    q[1, 1], v[1, 1] = 5.0, 0.3
    state.particle_q.assign(q)
    state.particle_qd.assign(v)
    win.apply_walls()
    lo, hi = win.bounds()[0]
    q, v = state.particle_q.numpy(), state.particle_qd.numpy()
    np.testing.assert_allclose([q[0, 0], v[0, 0], q[1, 1], v[1, 1]], [lo[0], 0.0, hi[1], 0.0], atol=1e-6)
    assert wp is not None


@pytest.mark.parametrize("name", ["basalt", "dry_sand_rough", "dry_sand_deep", "transition"])
def test_terrain_cfgs(name: str) -> None:
    """The paper's terrains: deep = 30 cm at tan 20 deg, rough has a surface, transition has three media."""
    t = terrain_cfg(name)
    if name == "dry_sand_deep":
        assert t.depth == 0.30 and t.mu_int is not None and np.isclose(t.mu_int, np.tan(np.radians(20.0)))
    if name == "dry_sand_rough":
        assert t.rough_amplitude > 0
    if name == "transition":
        assert t.materials == ("basalt", "dry_sand", "poppy_seed")
        np.testing.assert_array_equal(terrain_layer(t, np.array([0.0, 4.5, 7.5, 30.0])), [0, 1, 2, 2])


def _settle(win: SandWindow, state: Any, solver: Any, frames: int) -> None:
    """``frames`` MPM steps of 10 ms under gravity, walls applied after each (as the scene's frame does)."""
    for _ in range(frames):
        solver.step(state, state, None, None, 0.01)
        win.apply_walls()


def test_a_retired_lane_leaves_the_solve_and_the_others_do_not_notice() -> None:
    """Lane 1 retired (sand out of the solve), lane 0 settles exactly as with lane 1 in; a reseed brings it back.

    On the evaluation's rebuildable grid (fixed capacity) the retired lane's cells leave the grid. Retiring clears the ACTIVE flag of exactly lane 1's particles in the sand model and in the solver's transfer and
    material masks, and zeroes their material volume; its grains then stay where they are, while lane 0's sand
    (2 m away, no shared grid cell) moves as in a run where lane 1 stayed in. A reseed puts lane 1 back.
    """
    import newton

    lane_y = np.array([0.0, 2.0])
    runs, cells = [], []
    for retire in (False, True):
        win, model, state, solver = _window(terrain_cfg("dry_sand"), lane_y, capacity=200)
        q0 = state.particle_q.numpy().copy()
        if retire:
            win.set_lanes_active([1], False)
        _settle(win, state, solver, 3)
        runs.append((win, model, state, solver, q0, state.particle_q.numpy().copy()))
        # the grid's active cells (warp.fem's partition of the reserved capacity; -1 = unused slot)
        cells.append(int((solver._scratchpad.domain.geometry_partition._partition_cells.numpy() >= 0).sum()))
    assert cells[1] < 0.6 * cells[0]  # the retired lane's cells left the grid (60 -> 30 after one frame)
    per, active = runs[0][0].particles_per_robot, int(newton.ParticleFlags.ACTIVE)
    (_, _, _, _, q0_in, q_in), (win, model, state, solver, q0, q_out) = runs
    assert np.abs(q_in[per:] - q0_in[per:]).max() > 1e-4  # with lane 1 in, its sand moves in 30 ms
    np.testing.assert_array_equal(q_out[per:], q0[per:])  # retired: its grains stay where they were
    np.testing.assert_allclose(q_out[:per], q_in[:per], atol=1e-6)  # lane 0 unaffected
    mm = solver._mpm_model
    for arr in (model.particle_flags, mm.particle_flags, mm.material_particle_flags):
        f = arr.numpy()
        assert np.all(f[:per] & active) and not np.any(f[per:] & active)
    assert not mm.material_particle_volume.numpy()[per:].any() and win.retired == {1}
    import warp as wp

    win.reseed_lanes([1], [5], wp.array(_pelvis(np.zeros(2), lane_y, 2), dtype=wp.transform, device="cpu"))
    assert win.retired == set() and np.all(mm.particle_flags.numpy() & active)
    cached = mm.material_particle_volume.numpy().copy()
    mm.notify_particle_material_changed()
    np.testing.assert_allclose(cached, mm.material_particle_volume.numpy(), rtol=1e-5)
    with pytest.raises(ValueError, match="outside"):
        win.set_lanes_active([2], False)


def _columns_inside(win: SandWindow, robot: int) -> set[tuple[int, int]]:
    """Brute force: every world column whose centre lies inside robot ``robot``'s (turned) window rectangle."""
    centre, heading, half = win.frames()
    cx, cy = centre[robot, 0], centre[robot, 1] - win.lane_y[robot]
    c, s = np.cos(heading[robot]), np.sin(heading[robot])
    r = int(np.ceil(np.hypot(*half) / win.h)) + 2
    i0, j0 = int(np.floor(cx / win.h)), int(np.floor(cy / win.h))
    out = set()
    for i in range(i0 - r, i0 + r + 1):
        for j in range(j0 - r, j0 + r + 1):
            dx, dy = (i + 0.5) * win.h - cx, (j + 0.5) * win.h - cy
            if abs(c * dx + s * dy) < half[0] and abs(-s * dx + c * dy) < half[1]:
                out.add((i, j))
    return out


def _check_window(win: SandWindow, model: Any, state: Any, solver: Any, robot: int) -> None:
    """Robot ``robot``'s sand is exactly its window's columns, nz particles each, in the rectangle; the rest parked.

    A column kept through a turn keeps its grains, which lie within its cell: up to the cell's half diagonal h / sqrt(2)
    outside the turned rectangle, until the walls' clamp after the next MPM step.
    """
    import newton

    held = [tuple(c) for c in win.held_columns(robot).tolist()]
    assert set(held) == _columns_inside(win, robot) and len(held) == win.nz * len(set(held))
    assert len(set(held)) <= win.slots
    per, active = win.particles_per_robot, int(newton.ParticleFlags.ACTIVE)
    rows = slice(robot * per, (robot + 1) * per)
    live = win.column.numpy()[rows, 0] > -(2**30) + 1
    mm = solver._mpm_model
    for arr in (model.particle_flags, mm.particle_flags, mm.material_particle_flags):
        np.testing.assert_array_equal((arr.numpy()[rows] & active) != 0, live)
    assert not mm.material_particle_volume.numpy()[rows][~live].any()
    centre, heading, half = win.frames()
    q = state.particle_q.numpy()[rows][live]
    c, s = np.cos(heading[robot]), np.sin(heading[robot])
    dx, dy = q[:, 0] - centre[robot, 0], q[:, 1] - centre[robot, 1]
    tol = win.h / np.sqrt(2.0)
    assert np.all(np.abs(c * dx + s * dy) <= half[0] + tol) and np.all(np.abs(-s * dx + c * dy) <= half[1] + tol)
    cached = mm.material_particle_volume.numpy().copy()  # the solver's volume cache = a fresh notify's
    mm.notify_particle_material_changed()
    np.testing.assert_allclose(cached, mm.material_particle_volume.numpy(), rtol=1e-5)


def test_turned_window_holds_exactly_the_columns_inside_it() -> None:
    """Seeded at a 30 degree heading: the window is turned 30 degrees and holds every column centre inside it."""
    lane_y = np.array([0.0, 2.0])
    win, model, state, solver = _window(terrain_cfg("dry_sand"), lane_y, turn=True, heading=np.radians(30.0))
    # slots: 10 x 6 columns + ceil(sqrt(2) (10 + 6) + pi / 2) = 60 + 25 (window_slots' bound)
    assert win.slots == 85 and win.particles_per_robot == 85 * win.nz
    np.testing.assert_allclose(win.frames()[1], np.radians(30.0), atol=1e-6)
    for robot in (0, 1):
        _check_window(win, model, state, solver, robot)


def test_window_turns_with_the_robot_and_keeps_the_sand_it_still_covers() -> None:
    """A 2 degree yaw keeps the window (3 degree step); 20 degrees turn it: kept columns untouched, new ones seeded."""
    import warp as wp

    lane_y = np.array([0.0, 2.0])
    win, model, state, solver = _window(terrain_cfg("dry_sand"), lane_y, turn=True)
    before = {tuple(c) for c in win.held_columns(0).tolist()}
    q0, col0 = state.particle_q.numpy().copy(), win.column.numpy().copy()
    win.advance(wp.array(_pelvis(np.zeros(2), lane_y, 2, np.radians(2.0)), dtype=wp.transform, device="cpu"))
    np.testing.assert_array_equal(state.particle_q.numpy(), q0)  # within the step: nothing moves
    win.advance(wp.array(_pelvis(np.zeros(2), lane_y, 2, np.radians(20.0)), dtype=wp.transform, device="cpu"))
    np.testing.assert_allclose(win.frames()[1], np.radians(20.0), atol=1e-6)
    _check_window(win, model, state, solver, 0)
    after = {tuple(c) for c in win.held_columns(0).tolist()}
    assert before - after and after - before  # corners left, others entered
    per = win.particles_per_robot
    col = win.column.numpy()[:per]
    kept = np.array([tuple(c) in before & after for c in col.tolist()])
    same_slot = np.all(col == col0[:per], axis=1)
    np.testing.assert_array_equal(state.particle_q.numpy()[:per][kept & same_slot], q0[:per][kept & same_slot])
    assert (kept & same_slot).sum() == win.nz * len(before & after)  # a kept column keeps its slot
    # the new columns' particles carry the medium: mass rho_c h^2 hz (flat dry sand: hz = depth / nz)
    fresh = ~same_slot & (col[:, 0] > -(2**30) + 1)
    assert fresh.sum() == win.nz * len(after - before)
    np.testing.assert_allclose(model.particle_mass.numpy()[:per][fresh], 1500.0 * 0.05**3, rtol=1e-5)


def test_reseed_turns_a_lane_to_its_robot_at_once() -> None:
    """A refilled lane's window snaps to its robot's heading (90 degrees), the other lane keeps its window."""
    import warp as wp

    lane_y = np.array([0.0, 2.0])
    win, model, state, solver = _window(terrain_cfg("poppy_seed"), lane_y, turn=True)
    q0 = state.particle_q.numpy().copy()
    win.set_lanes_active([0], False)
    pose = _pelvis(np.zeros(2), lane_y, 2, np.array([np.pi / 2, 0.0]))
    win.reseed_lanes([0], [3], wp.array(pose, dtype=wp.transform, device="cpu"))
    np.testing.assert_allclose(win.frames()[1], [np.pi / 2, 0.0], atol=1e-6)
    assert win.retired == set()
    _check_window(win, model, state, solver, 0)
    per = win.particles_per_robot
    np.testing.assert_array_equal(state.particle_q.numpy()[per:], q0[per:])


def test_reach_within_window_accounts_for_the_turn_lag() -> None:
    """1.4 x 0.6 m, lead 0.2 m: a (0.45, 0.85, 0.26) m reach fits a window on the heading, not one lagging 3 deg.

    Front corner (0.85, 0.26) turned by 3 deg: v = 0.85 sin 3 + 0.26 cos 3 = 0.0445 + 0.2596 = 0.3041 > 0.3 m.
    """
    from gmloco.eval.mpm.window import reach_within_window

    cfg = SandWindowCfg(length=1.4, width=0.6, lead=0.2, turn_step=np.radians(3.0))
    assert reach_within_window(cfg, (0.45, 0.85, 0.25))  # v = 0.0445 + 0.2497 = 0.2942 m
    assert not reach_within_window(cfg, (0.45, 0.85, 0.26))
    assert reach_within_window(SandWindowCfg(length=1.4, width=0.6, lead=0.2, turn_with_robot=False),
                               (0.45, 0.85, 0.26))  # fmt: skip
    assert not reach_within_window(cfg, (0.45, 0.95, 0.1))  # 0.95 - 0.2 > 0.7 m ahead of the centre


def test_turned_walls_clamp_in_the_window_frame_and_turn_their_body() -> None:
    """Window turned 90 deg: a grain pushed 0.1 m past its far side wall comes back onto it, outward speed dropped.

    At psi_w = 90 deg the window's u axis is world +y: the 0.5 m side spans y in lane +-0.25 m about its centre,
    the 0.3 m side x +-0.15 m. A grain at u = 0.35 m (0.1 m past the u = 0.25 m wall) moving outward at 0.5 m/s and
    sideways at 0.2 m/s ends at u = 0.25 m with the sideways speed kept. The wall body turns by 90 deg about z.
    """
    import warp as wp

    lane_y = np.array([0.0, 2.0])
    win, _, state, _ = _window(terrain_cfg("dry_sand"), lane_y, turn=True, heading=np.pi / 2)
    centre, heading, half = win.frames()
    np.testing.assert_allclose(half, [0.25, 0.15])
    q, v = state.particle_q.numpy(), state.particle_qd.numpy()
    q[0, :2] = centre[0] + [0.05, 0.35]  # u = +0.35 m (world +y), v = -0.05 m
    v[0, :2] = [0.2, 0.5]  # world (x, y): sideways -0.2 m/s in v, outward +0.5 m/s in u
    state.particle_q.assign(q)
    state.particle_qd.assign(v)
    win.apply_walls()
    q, v = state.particle_q.numpy(), state.particle_qd.numpy()
    np.testing.assert_allclose(q[0, :2], centre[0] + [0.05, 0.25], atol=1e-6)
    np.testing.assert_allclose(v[0, :2], [0.2, 0.0], atol=1e-6)
    body_q = wp.zeros(3, dtype=wp.transform, device="cpu")
    body_qd = wp.zeros(3, dtype=wp.spatial_vector, device="cpu")
    win.place_walls(1, body_q, body_qd)
    pose = body_q.numpy()
    np.testing.assert_allclose(pose[1, :2], centre[0], atol=1e-6)
    np.testing.assert_allclose(pose[1, 3:], [0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)], atol=1e-6)  # x y z w
    np.testing.assert_allclose(heading, np.pi / 2, atol=1e-6)
