# SPDX-License-Identifier: Apache-2.0
"""Sand windows: each robot walks on its own patch of MPM sand, static (a full bed) or moving with it.

A moving window holds a fixed number of particles: ``nx x ny`` columns around the pelvis (``lead`` ahead of it),
``nz`` particles per column. When the robot advances one column width, the particles of the column it left
behind are re-seeded as the column that enters at the front (:mod:`gmloco.eval.mpm.kernels_window`), with the
terrain's surface height and medium there. Frictionless side walls move with the window. The cost of a 10 s walk
is then that of a bed the window's size, whatever the course length. Several robots share one MPM solver, each in
its own lane (``lane_y``), far enough apart that their sand never meets.

Static windows (``moving=False``) are the naive baseline: a bed covering the whole course, built the same way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from gmloco.eval.mpm.window_terrain import TerrainCfg, terrain_materials

__all__ = ["SandWindow", "SandWindowCfg"]

_UNSEEDED = -(2**30)


@dataclass(frozen=True)
class SandWindowCfg:
    """Sand patch of each robot."""

    moving: bool = True
    """Recentre the window on the robot every frame (recycling columns); False = a static bed."""
    length: float = 1.8
    """Window size along x [m] (default: the rear wall 0.7 m behind the pelvis, beyond a trailing foot's reach)."""
    width: float = 1.0
    """Window size along y [m]."""
    lead: float = 0.2
    """Window centre ahead of the pelvis along its heading [m] (static: at the start)."""
    offset_y: float = 0.0
    """Window centre left of the pelvis heading [m] (static beds around a circular course)."""
    particles_per_voxel: int = 2
    """Particles per voxel edge (8 per cell at 2)."""
    jitter: float = 0.5
    """Random particle offset as a fraction of the spacing [-]."""


class SandWindow:
    """The particles of every robot's window, their slot bookkeeping and the kernels that move them."""

    def __init__(
        self,
        cfg: SandWindowCfg,
        terrain: TerrainCfg,
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
        self.num_robots = len(lane_y)
        self.particles_per_robot = self.nx * self.ny * self.nz
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
        """Device arrays: the window struct, origins per robot and the column of every particle."""
        from gmloco.eval.mpm.kernels_window import WindowArrays

        t, w = self.terrain, WindowArrays()
        w.nx, w.ny, w.nz, w.h, w.depth = self.nx, self.ny, self.nz, float(self.h), float(t.depth)
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
        self.column = wp.full(self.particle_count, wp.vec2i(_UNSEEDED, _UNSEEDED), dtype=wp.vec2i, device=device)

    def seed_model(self, wp: Any, sand_model: Any, body_q: Any) -> None:
        """Place the windows around the robots' initial poses and fill them (before the MPM solver exists)."""
        from gmloco.eval.mpm.kernels_window import eval_window_origin, eval_window_recycle

        eval_window_origin(self.arrays, True, body_q, self.origin)
        n, dev = self.particle_count, sand_model.device
        scratch = tuple(wp.zeros(n, dtype=float, device=dev) for _ in range(3))
        m = sand_model.mpm
        eval_window_recycle(
            self.arrays, self.origin, self.column,
            (sand_model.particle_q, sand_model.particle_qd, m.particle_qd_grad, m.particle_elastic_strain,
             m.particle_Jp, m.particle_stress, m.particle_transform),
            (sand_model.particle_mass, sand_model.particle_radius, m.friction, *scratch),
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
        self._model_arrays = (sand_model.particle_mass, sand_model.particle_radius, m.friction,
                              mm.particle_volume, mm.particle_density, mm.material_particle_volume)  # fmt: skip
        self._sand_state = sand_state
        self._flag_arrays = (sand_model.particle_flags, mm.particle_flags, mm.material_particle_flags)
        self._volumes = (mm.particle_volume, mm.material_particle_volume)
        self.retired: set[int] = set()

    def advance(self, body_q: Any) -> None:
        """Recentre moving windows on the robots and recycle the columns they left (graph-capturable)."""
        from gmloco.eval.mpm.kernels_window import eval_window_origin, eval_window_recycle

        if not self.cfg.moving:
            return
        eval_window_origin(self.arrays, True, body_q, self.origin)
        eval_window_recycle(self.arrays, self.origin, self.column, self._state_arrays, self._model_arrays)

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

        Moving windows are recentred on the robots' poses ``body_q`` (as every frame does); static beds keep their
        place. ``seeds`` are jitter seed offsets, so a refilled lane gets new grains; a retired lane
        (:meth:`set_lanes_active`) rejoins the solve. Needs :meth:`bind`; runs outside a captured frame (host copies).
        """
        import warp as wp

        from gmloco.eval.mpm.kernels_window import eval_window_origin, eval_window_recycle

        if len(lanes) != len(seeds):
            raise ValueError(f"reseed_lanes: {len(lanes)} lanes but {len(seeds)} seeds")
        lane_seed = self.arrays.lane_seed.numpy()
        column = self.column.numpy()
        for r, sd in zip(lanes, seeds, strict=True):
            if not 0 <= r < self.num_robots:
                raise ValueError(f"reseed_lanes: lane {r} outside 0..{self.num_robots - 1}")
            lane_seed[r] = sd
            column[r * self.particles_per_robot : (r + 1) * self.particles_per_robot] = _UNSEEDED
        self.arrays.lane_seed.assign(lane_seed)
        self.column.assign(wp.array(column, dtype=wp.vec2i, device=self.column.device))
        self.set_lanes_active(sorted(self.retired & set(lanes)), True)
        eval_window_origin(self.arrays, self.cfg.moving, body_q, self.origin)
        eval_window_recycle(self.arrays, self.origin, self.column, self._state_arrays, self._model_arrays)

    def wall_boxes(self, thickness: float, height: float) -> list[tuple[tuple[float, ...], tuple[float, ...]]]:
        """The four walls of a window as (centre, half extents) boxes [m] in its wall-body frame.

        The frame sits at the window's lower (x, y) corner at z = 0; the walls enclose ``nx h x ny h`` from the
        floor z = -depth up to ``height`` above z = 0 and are ``2 thickness`` thick.
        """
        length, width, t = self.nx * self.h, self.ny * self.h, thickness
        hz = 0.5 * (self.terrain.depth + height)
        cz = -self.terrain.depth + hz
        return [
            ((-t, 0.5 * width, cz), (t, 0.5 * width + 2 * t, hz)),
            ((length + t, 0.5 * width, cz), (t, 0.5 * width + 2 * t, hz)),
            ((0.5 * length, -t, cz), (0.5 * length, t, hz)),
            ((0.5 * length, width + t, cz), (0.5 * length, t, hz)),
        ]

    def place_walls(self, body_offset: int, body_q: Any, body_qd: Any) -> None:
        """Write every robot's wall body pose (index ``body_offset + r``) from its window origin."""
        from gmloco.eval.mpm.kernels_window import eval_window_wall_pose

        eval_window_wall_pose(self.arrays, self.origin, body_offset, body_q, body_qd)

    def apply_walls(self) -> None:
        """Clamp the sand into each window (after the MPM step)."""
        from gmloco.eval.mpm.kernels_window import eval_window_walls

        eval_window_walls(self.arrays, self.origin, self._sand_state.particle_q, self._sand_state.particle_qd)

    def bounds(self) -> np.ndarray:
        """Window boxes [R, 2, 2]: (lower, upper) xy corners [m] of each robot's window now."""
        o = self.origin.numpy().astype(np.float64)
        lo = o * self.h + np.stack([np.zeros(self.num_robots), self.lane_y], axis=1)
        return np.stack([lo, lo + np.array([self.nx, self.ny]) * self.h], axis=1)
