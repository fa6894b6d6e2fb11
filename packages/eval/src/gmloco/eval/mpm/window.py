# SPDX-License-Identifier: Apache-2.0
"""Sand windows: each robot walks on its own patch of MPM sand, static (a full bed) or moving with it.

A moving window is a rectangle of ``nx x ny`` columns around the pelvis (``lead`` ahead of it) that turns with
the robot: its heading follows the robot's whenever the two differ by more than ``turn_step``, so the window
covers the same reach ahead, behind and beside the robot whatever way it walks (straight, circle, drift). Its
particles (``nz`` per column) sit in a fixed set of slots: when the robot advances or turns, the slots of the
columns that left the rectangle are re-seeded, stress-free, in the columns that entered it
(:mod:`gmloco.eval.mpm.kernels_window`), with the terrain's surface height and medium there; columns that stay
are untouched. Frictionless walls on the rectangle's sides move and turn with it. The cost of a 10 s walk is that
of a bed the window's size, whatever the course length or heading. Several robots share one MPM solver, each in
its own lane (``lane_y``), far enough apart that their sand never meets, turned or not. ``turn_with_robot=False``
keeps the window's sides on the grid's axes (a box that does not turn).

Static windows (``moving=False``) are the naive baseline: a bed covering the whole course, built the same way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gmloco.eval.mpm.window_terrain import MpmTerrainCfg, terrain_materials

__all__ = ["SandWindow", "SandWindowCfg", "reach_within_window", "window_grid", "window_slots"]

_UNSEEDED = -(2**30)
"""``kernels_window.FREE_COLUMN``: a free slot, a parked particle (kept here: importing warp is lazy)."""
_STALE = _UNSEEDED + 1
"""Column of a particle whose state is not known yet: the next recycle re-seeds or parks it."""


def window_slots(nx: int, ny: int, turns: bool) -> int:
    """Slot columns of a window of ``nx x ny`` columns: the most column centres a turned rectangle can hold.

    Each held centre's h x h cell lies in the rectangle grown by h / sqrt(2) (the cell's half diagonal), so
    N h^2 <= nx ny h^2 + 2 (nx + ny) h^2 / sqrt(2) + pi h^2 / 2, i.e. N <= nx ny + sqrt(2) (nx + ny) + pi / 2
    (Minkowski sum with a disc). A window on the grid's axes holds exactly nx ny.
    """
    return nx * ny + (math.ceil(math.sqrt(2.0) * (nx + ny) + 0.5 * math.pi) if turns else 0)


def window_grid(nx: int, ny: int) -> int:
    """Side of the patch of columns the allocation sweeps around a window: its half diagonal plus 2, doubled."""
    return 2 * (math.ceil(0.5 * math.hypot(nx, ny)) + 2)


def reach_within_window(cfg: SandWindowCfg, reach: tuple[float, float, float], margin: float = 0.0) -> bool:
    """Whether the soles' reach lies inside a moving window whose heading lags the robot's by up to ``turn_step``.

    ``reach``: (behind, ahead, beside) the pelvis along its heading [m] (``g1.soles.sole_reach``); the reach box
    [-behind, ahead] x [-beside, beside] is turned by the worst lag (0 for a window that does not turn) about the
    pelvis and must lie within the rectangle ``length x width`` centred ``lead`` ahead of it, less ``margin`` [m]
    (e.g. half a column for the window's whole-column steps).
    """
    behind, ahead, side = reach
    lag = cfg.turn_step if cfg.turn_with_robot else 0.0
    hl, hw = 0.5 * cfg.length - margin, 0.5 * cfg.width - margin
    for d in (-lag, lag):
        c, s = math.cos(d), math.sin(d)
        for x in (-behind, ahead):
            for y in (-side, side):
                u, v = c * x - s * y - cfg.lead, s * x + c * y - cfg.offset_y
                if abs(u) > hl or abs(v) > hw:
                    return False
    return True


@dataclass(frozen=True)
class SandWindowCfg:
    """Sand patch of each robot."""

    moving: bool = True
    """Recentre the window on the robot every frame (recycling columns); False = a static bed."""
    turn_with_robot: bool = True
    """Turn the moving window with the robot's heading (False: its sides stay on the grid's axes)."""
    turn_step: float = field(default=math.radians(3.0), metadata={"ge": 0})
    """Heading change of the robot that turns the window to it [rad]: the window lags the heading by at most this,
    and the gait's yaw sway below it does not re-seed the window's corners every step."""
    length: float = field(default=1.8, metadata={"gt": 0})
    """Window size along the robot's heading [m] (default: the rear wall 0.7 m behind the pelvis, beyond a trailing
    foot's reach; along x for a window that does not turn)."""
    width: float = field(default=1.0, metadata={"gt": 0})
    """Window size across the robot's heading [m] (along y for a window that does not turn)."""
    lead: float = field(default=0.2, metadata={"ge": -5, "le": 5})
    """Window centre ahead of the pelvis along its heading [m] (static: at the start)."""
    offset_y: float = 0.0
    """Window centre left of the pelvis heading [m] (static beds around a circular course)."""
    particles_per_voxel: int = field(default=2, metadata={"ge": 1})
    """Particles per voxel edge (8 per cell at 2)."""
    jitter: float = field(default=0.5, metadata={"ge": 0, "le": 1})
    """Random particle offset as a fraction of the spacing [-]."""


class SandWindow:
    """The particles of every robot's window, their slot bookkeeping and the kernels that move them."""

    def __init__(
        self,
        cfg: SandWindowCfg,
        terrain: MpmTerrainCfg,
        voxel_size: float,
        lane_y: np.ndarray,
        bodies_per_robot: int,
        seed: int = 0,
    ) -> None:
        """Size the lattice (column width h = voxel_size / particles_per_voxel) for ``len(lane_y)`` robots."""
        self.cfg, self.terrain = cfg, terrain
        self.h = voxel_size / cfg.particles_per_voxel
        self.nx = max(1, math.ceil(cfg.length / self.h))
        self.ny = max(1, math.ceil(cfg.width / self.h))
        self.nz = max(1, round(terrain.depth / self.h))
        self.turns = cfg.moving and cfg.turn_with_robot
        self.slots = window_slots(self.nx, self.ny, self.turns)
        self.grid = window_grid(self.nx, self.ny)
        self.num_robots = len(lane_y)
        self.particles_per_robot = self.slots * self.nz
        self.particle_count = self.num_robots * self.particles_per_robot
        self.lane_y = np.asarray(lane_y, dtype=np.float64)
        self.bodies_per_robot = bodies_per_robot
        self.seed = seed
        self.materials = terrain_materials(terrain)

    def add_particles(self, builder: Any) -> None:
        """Add placeholder particles (positions and masses are written by :meth:`seed`)."""
        n = self.particle_count
        zeros = np.zeros((n, 3))
        builder.add_particles(zeros.tolist(), zeros.tolist(), [1.0] * n, [0.5 * self.h] * n)

    def allocate(self, wp: Any, device: Any) -> None:
        """Device arrays: the window struct, origin and heading per robot, slot and particle columns, scratch."""
        import newton

        from gmloco.eval.mpm.kernels_window import WindowArrays

        t, w = self.terrain, WindowArrays()
        w.nx, w.ny, w.nz, w.h, w.depth = self.nx, self.ny, self.nz, float(self.h), float(t.depth)
        w.slots, w.grid, w.turn, w.turn_step = self.slots, self.grid, int(self.turns), float(self.cfg.turn_step)
        w.active_flag = int(newton.ParticleFlags.ACTIVE)
        w.lane_active = wp.ones(self.num_robots, dtype=int, device=device)
        w.lead, w.seed, w.jitter = float(self.cfg.lead), int(self.seed), float(self.cfg.jitter)
        w.offset_y = float(self.cfg.offset_y)
        w.bodies_per_robot = int(self.bodies_per_robot)
        w.lane_y = wp.array(self.lane_y.astype(np.float32), dtype=float, device=device)
        w.lane_seed = wp.zeros(self.num_robots, dtype=int, device=device)
        w.rough_amplitude = float(t.rough_amplitude)
        w.rough_k = float(2.0 * math.pi / t.rough_wavelength)
        w.layer_start, w.layer_length = float(t.layer_start), float(t.layer_length)
        w.layer_density = wp.array([m.density for m in self.materials], dtype=float, device=device)
        w.layer_friction = wp.array([m.friction for m in self.materials], dtype=float, device=device)
        self.arrays = w
        self.origin = wp.zeros(self.num_robots, dtype=wp.vec2i, device=device)
        self.heading = wp.full(self.num_robots, math.nan, dtype=float, device=device)
        """Window heading psi_w per robot [rad] (NaN: snap to the robot's at the next placement)."""
        unseeded = wp.vec2i(_UNSEEDED, _UNSEEDED)
        self.slot_column = wp.full(self.num_robots * self.slots, unseeded, dtype=wp.vec2i, device=device)
        self.column = wp.full(self.particle_count, wp.vec2i(_STALE, _STALE), dtype=wp.vec2i, device=device)
        self._alloc_scratch = (wp.zeros(self.num_robots * self.slots, dtype=int, device=device),
                               wp.zeros(self.num_robots * self.grid**2, dtype=int, device=device))  # fmt: skip

    def _place(self, body_q: Any, track: bool) -> None:
        """Window origins and headings from the poses, then the slots matched to the windows' columns."""
        from gmloco.eval.mpm.kernels_window import eval_window_allocate, eval_window_origin

        eval_window_origin(self.arrays, track, body_q, self.origin, self.heading)
        eval_window_allocate(self.arrays, self.origin, self.heading, self.slot_column, self._alloc_scratch)

    def seed_model(self, wp: Any, sand_model: Any, body_q: Any) -> None:
        """Place the windows around the robots' initial poses and fill them (before the MPM solver exists)."""
        from gmloco.eval.mpm.kernels_window import eval_window_recycle

        self._place(body_q, True)
        n, dev = self.particle_count, sand_model.device
        scratch = tuple(wp.zeros(n, dtype=float, device=dev) for _ in range(3))
        flags = tuple(wp.zeros(n, dtype=wp.int32, device=dev) for _ in range(2))
        m = sand_model.mpm
        eval_window_recycle(
            self.arrays, self.origin, self.heading, self.slot_column, self.column,
            (sand_model.particle_q, sand_model.particle_qd, m.particle_qd_grad, m.particle_elastic_strain,
             m.particle_Jp, m.particle_stress, m.particle_transform),
            (sand_model.particle_mass, sand_model.particle_radius, m.friction, *scratch, sand_model.particle_flags,
             *flags),
        )  # fmt: skip

    def bind(self, sand_model: Any, sand_state: Any, mpm_solver: Any) -> None:
        """Remember the arrays a recycle writes: the sand state's and the MPM solver's cached particle volumes.

        ``SolverImplicitMPM`` caches particle volume and density at construction
        (``notify_particle_material_changed``); a re-seeded particle's are written alongside its mass and radius,
        so the cache stays what a fresh notify would compute (checked by the window tests).
        """
        s, m, mm = sand_state.mpm, sand_model.mpm, mpm_solver._mpm_model
        self._state_arrays = (sand_state.particle_q, sand_state.particle_qd, s.particle_qd_grad,
                              s.particle_elastic_strain, s.particle_Jp, s.particle_stress,
                              s.particle_transform)  # fmt: skip
        self._flag_arrays = (sand_model.particle_flags, mm.particle_flags, mm.material_particle_flags)
        self._model_arrays = (sand_model.particle_mass, sand_model.particle_radius, m.friction,
                              mm.particle_volume, mm.particle_density, mm.material_particle_volume,
                              *self._flag_arrays)  # fmt: skip
        self._sand_state = sand_state
        self._volumes = (mm.particle_volume, mm.material_particle_volume)
        self.retired: set[int] = set()

    def advance(self, body_q: Any) -> None:
        """Recentre and turn moving windows with the robots and recycle the columns they left (graph-capturable)."""
        if not self.cfg.moving:
            return
        self._place(body_q, True)
        self._recycle()

    def _recycle(self) -> None:
        """Re-seed the slots whose column changed, park the free ones (needs :meth:`bind`)."""
        from gmloco.eval.mpm.kernels_window import eval_window_recycle

        eval_window_recycle(self.arrays, self.origin, self.heading, self.slot_column, self.column, self._state_arrays,
                            self._model_arrays)  # fmt: skip

    def set_lanes_active(self, lanes: list[int], active: bool) -> None:
        """Take the sand of ``lanes`` out of the MPM solve (``active=False``) or put it back (``True``).

        An inactive particle is neither transferred to the grid nor advected, and the rebuildable sparse grid
        allocates no cell for it: a lane whose robot has no episode left stops costing its share of the transfers
        and of the rheology solve's active cells (its robot loses its support; its frames are no longer scored).
        The other lanes' sand never shares a cell with it (lanes are ``lane_gap`` apart). The flags (sand model,
        solver's transfer and material masks) and the solver's material volumes are written in place, so a captured
        CUDA graph reads the new values. Needs :meth:`bind`; runs outside a captured frame (host copies).
        """
        import newton

        if not hasattr(self, "_flag_arrays"):
            raise RuntimeError("set_lanes_active needs bind() first (the MPM solver's particle arrays)")
        bad = [r for r in lanes if not 0 <= r < self.num_robots]
        if bad:
            raise ValueError(f"set_lanes_active: lanes {bad} outside 0..{self.num_robots - 1}")
        if not lanes:
            return
        flag, per = int(newton.ParticleFlags.ACTIVE), self.particles_per_robot
        rows = np.concatenate([np.arange(r * per, (r + 1) * per) for r in lanes])
        if active:  # parked particles (free slots of a turned window) stay out
            rows = rows[self.column.numpy()[rows, 0] != _UNSEEDED]
        lane_active = self.arrays.lane_active.numpy()
        lane_active[lanes] = int(active)
        self.arrays.lane_active.assign(lane_active)
        for arr in self._flag_arrays:
            f = arr.numpy()
            f[rows] = (f[rows] | flag) if active else (f[rows] & ~flag)
            arr.assign(f)
        volume, material_volume = (a.numpy() for a in self._volumes)
        material_volume[rows] = volume[rows] if active else 0.0
        self._volumes[1].assign(material_volume)
        self.retired = self.retired - set(lanes) if active else self.retired | set(lanes)

    def reseed_lanes(self, lanes: list[int], seeds: list[int], body_q: Any) -> None:
        """Fill the windows of ``lanes`` with fresh, stress-free sand (a new episode there); other lanes keep theirs.

        Moving windows are recentred on the robots' poses ``body_q`` and turned to their headings (as every frame
        does); static beds keep their place. ``seeds`` are jitter seed offsets, so a refilled lane gets new grains; a retired lane
        (:meth:`set_lanes_active`) rejoins the solve. Needs :meth:`bind`; runs outside a captured frame (host copies).
        """
        import warp as wp

        if len(lanes) != len(seeds):
            raise ValueError(f"reseed_lanes: {len(lanes)} lanes but {len(seeds)} seeds")
        lane_seed, heading = self.arrays.lane_seed.numpy(), self.heading.numpy()
        column, slot_column = self.column.numpy(), self.slot_column.numpy()
        for r, sd in zip(lanes, seeds, strict=True):
            if not 0 <= r < self.num_robots:
                raise ValueError(f"reseed_lanes: lane {r} outside 0..{self.num_robots - 1}")
            lane_seed[r] = sd
            column[r * self.particles_per_robot : (r + 1) * self.particles_per_robot] = _STALE
            slot_column[r * self.slots : (r + 1) * self.slots] = _UNSEEDED
            if self.turns:
                heading[r] = math.nan  # the window turns to the robot's heading at once
        self.arrays.lane_seed.assign(lane_seed)
        self.heading.assign(heading)
        dev = self.column.device
        self.column.assign(wp.array(column, dtype=wp.vec2i, device=dev))
        self.slot_column.assign(wp.array(slot_column, dtype=wp.vec2i, device=dev))
        retired = sorted(self.retired & set(lanes))
        if retired:  # back in the solve (the re-seed below activates their new sand)
            lane_active = self.arrays.lane_active.numpy()
            lane_active[retired] = 1
            self.arrays.lane_active.assign(lane_active)
            self.retired -= set(retired)
        self._place(body_q, self.cfg.moving)
        self._recycle()

    def wall_boxes(self, thickness: float, height: float) -> list[tuple[tuple[float, ...], tuple[float, ...]]]:
        """The four walls of a window as (centre, half extents) boxes [m] in its wall-body frame.

        The frame sits at the window's centre at z = 0, x along the window heading; the walls enclose
        ``nx h x ny h`` from the floor z = -depth up to ``height`` above z = 0 and are ``2 thickness`` thick.
        """
        hl, hw, t = 0.5 * self.nx * self.h, 0.5 * self.ny * self.h, thickness
        hz = 0.5 * (self.terrain.depth + height)
        cz = -self.terrain.depth + hz
        return [
            ((-hl - t, 0.0, cz), (t, hw + 2 * t, hz)),
            ((hl + t, 0.0, cz), (t, hw + 2 * t, hz)),
            ((0.0, -hw - t, cz), (hl, t, hz)),
            ((0.0, hw + t, cz), (hl, t, hz)),
        ]

    def place_walls(self, body_offset: int, body_q: Any, body_qd: Any) -> None:
        """Write every robot's wall body pose (index ``body_offset + r``) from its window origin and heading."""
        from gmloco.eval.mpm.kernels_window import eval_window_wall_pose

        eval_window_wall_pose(self.arrays, self.origin, self.heading, body_offset, body_q, body_qd)

    def apply_walls(self) -> None:
        """Clamp the sand into each window (after the MPM step)."""
        from gmloco.eval.mpm.kernels_window import eval_window_walls

        eval_window_walls(self.arrays, self.origin, self.heading, self._sand_state.particle_q,
                          self._sand_state.particle_qd)  # fmt: skip

    def frames(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Each robot's window now: centre [R, 2] (world xy [m]), heading [R] [rad], half extents [2] [m]."""
        o = self.origin.numpy().astype(np.float64)
        centre = (o + 0.5 * np.array([self.nx, self.ny])) * self.h + np.stack(
            [np.zeros(self.num_robots), self.lane_y], axis=1
        )
        heading = np.nan_to_num(self.heading.numpy().astype(np.float64))
        return centre, heading, 0.5 * self.h * np.array([self.nx, self.ny], dtype=np.float64)

    def bounds(self) -> np.ndarray:
        """Axis-aligned boxes around the windows [R, 2, 2]: (lower, upper) xy corners [m] (the windows when unturned)."""
        centre, heading, half = self.frames()
        c, s = np.abs(np.cos(heading)), np.abs(np.sin(heading))
        ext = np.stack([c * half[0] + s * half[1], s * half[0] + c * half[1]], axis=1)
        return np.stack([centre - ext, centre + ext], axis=1)

    def held_columns(self, robot: int) -> np.ndarray:
        """World columns (I, J) robot ``robot``'s particles stand for now (parked ones left out), [n, 2]."""
        per = self.particles_per_robot
        col = self.column.numpy()[robot * per : (robot + 1) * per]
        return col[col[:, 0] > _STALE]
