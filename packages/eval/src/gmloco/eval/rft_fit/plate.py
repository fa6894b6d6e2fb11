# SPDX-License-Identifier: Apache-2.0
"""MPM plate intrusion at constant velocity: a kinematic thin plate pushed through a sand bed.

The plate is a *kinematic* collider body of Newton's implicit MPM (``is_kinematic=True``: zero effective mass,
so the sand cannot change its motion); its pose and velocity are prescribed every frame. The force of the sand
on the plate is the sum of the plate's collider-node impulses divided by the frame time, harvested exactly as
in the box scene (``kernels_coupling.eval_body_sand_wrench``).

Newton 1.5.2 pitfall (the cause of issue 5's "zero plate force"): without a CUDA graph the rheology loop runs
``max_iterations // 25`` Gauss-Seidel batches, so ``max_iterations < 25`` means no contact solve at all
(``MpmSolverCfg`` now refuses it).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from gmloco.eval.mpm.bed import SandBedCfg, add_bed_container
from gmloco.eval.mpm.box_scene import MpmSolverCfg, emit_bed_particles
from gmloco.eval.mpm.coupled_setup import make_mpm_solver
from gmloco.eval.mpm.materials import GranularMaterial, MpmMaterialCfg, apply_mpm_material, mpm_material

__all__ = [
    "PlateIntrusionCfg",
    "PlateRun",
    "plate_path",
    "plate_rotation",
    "run_plate_intrusion",
    "run_plate_intrusions",
]


@dataclass(frozen=True)
class PlateIntrusionCfg:
    """One family of constant-velocity plate intrusions (geometry and numerics; direction per run)."""

    plate_size: float = 0.1
    """Square plate edge L [m]."""
    plate_thickness: float = 0.01
    """Plate thickness [m]."""
    speed: float = 0.5
    """Intrusion speed [m/s]. Quasi-static: the inertial stress rho v^2 (375 Pa for dry sand) is < 1 % of the
    RFT stress xi_n d (~1.6e5 Pa at 0.1 m), and 5 mm per 100 Hz frame stays below a quarter voxel at 2 cm."""
    depth_range: tuple[float, float] = (0.08, 0.2)
    """Centroid depths [m] at which steady stresses are sampled."""
    travel_before_sampling: float = 0.1
    """Distance the plate moves before samples count (leaves the carved start cavity) [m]."""
    plate_friction: float | None = None
    """Plate-sand Coulomb friction [-]; None = the medium's mu_surf (the fit then uses only the normal stress of
    samples that sit on this friction limit, see ``rft_fit.run``)."""
    bed: SandBedCfg = field(default_factory=lambda: SandBedCfg(size_x=0.7, size_y=0.7, depth=0.35, center_x=0.0))
    """Sand bed (surface z = 0); the plate path is centred in it."""
    solver: MpmSolverCfg = field(default_factory=lambda: MpmSolverCfg(voxel_size=0.02, max_iterations=250))
    """MPM numerics. The plate force grows with the rheology iterations (Gauss-Seidel not converged; README):
    vertical plate, 4 cm voxels, G_z = 0.25 / 0.31 / 0.39 / 0.46 / 0.50 / 0.54 at 25 / 50 / 100 / 200 / 400 / 800."""
    device: str | None = None
    """Warp device; None = Warp's default."""


@dataclass
class PlateRun:
    """Logged samples of one plate intrusion."""

    normal: np.ndarray
    """Plate normal (one face; the leading face is +-normal) [-], [3]."""
    velocity: np.ndarray
    """Plate velocity [m/s], [3]."""
    depth: np.ndarray
    """Centroid depth below the surface at each frame [m], [T]."""
    force: np.ndarray
    """Force of the sand on the plate [N], [T, 3]."""
    sampled: np.ndarray
    """Frames inside the steady window, bool [T]."""
    particle_count: int
    """MPM particles."""
    wall_time: float
    """Wall-clock time of the run, construction included [s] (batched runs: the batch's / its size)."""
    frames_per_s: float
    """Simulated frames per wall-clock second of the stepping loop [1/s]."""


def plate_rotation(normal: np.ndarray) -> np.ndarray:
    """Return a rotation matrix whose local z axis is ``normal`` [3, 3]."""
    z = np.asarray(normal, dtype=np.float64) / np.linalg.norm(normal)
    ref = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(ref, z)
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z], axis=1)


def plate_path(cfg: PlateIntrusionCfg, velocity: np.ndarray) -> tuple[np.ndarray, float]:
    """Return the start centroid [m] [3] and the duration [s] so that the sampled path spans the depth range."""
    v_hat = np.asarray(velocity, dtype=np.float64) / np.linalg.norm(velocity)
    d_lo, d_hi = cfg.depth_range
    vz = v_hat[2]
    if abs(vz) > 1e-3:  # vertical component: traverse the depth range, plus the lead-in distance
        end = np.array([0.0, 0.0, -(d_hi if vz < 0 else d_lo)])
        length = (d_hi - d_lo) / abs(vz) + cfg.travel_before_sampling
    else:  # horizontal: constant mid depth
        end = np.array([0.0, 0.0, -0.5 * (d_lo + d_hi)])
        length = cfg.travel_before_sampling + 2.0 * cfg.plate_size
    start = end - v_hat * length
    centre = start + 0.5 * v_hat * length
    start[:2] -= centre[:2]  # centre the path horizontally in the bed
    start[:2] += np.array([cfg.bed.center_x, cfg.bed.center_y])
    return start, length / cfg.speed


def _build_colliders(newton: Any, wp: Any, cfg: PlateIntrusionCfg, poses: list[tuple[np.ndarray, np.ndarray]],
                     offsets: np.ndarray, friction: float, mat: MpmMaterialCfg) -> tuple[Any, list[int]]:  # fmt: skip
    """Collider model: one kinematic plate per region plus each region's static walls (one floor plane)."""
    from gmloco.eval.mpm.box_scene import _add_region_walls, _shifted_bed

    builder = newton.ModelBuilder()
    half = 0.5 * np.array([cfg.plate_size, cfg.plate_size, cfg.plate_thickness])
    shape = newton.ModelBuilder.ShapeConfig(density=0.0, mu=float(friction))
    bodies = []
    for start, rot in poses:
        xform = wp.transform(wp.vec3(*start.tolist()), wp.quat(*_quat_xyzw(rot)))
        body = builder.add_body(xform=xform, is_kinematic=True, label="plate")
        builder.add_shape_box(body, hx=float(half[0]), hy=float(half[1]), hz=float(half[2]), cfg=shape)
        bodies.append(body)
    add_bed_container(builder, cfg.bed, friction=mat.friction)
    for off in offsets[1:]:
        _add_region_walls(newton, wp, builder, _shifted_bed(cfg.bed, off), mat.friction)
    return builder.finalize(), bodies


def _plate_offsets(cfg: PlateIntrusionCfg, count: int) -> np.ndarray:
    """Region offsets [m] [count, 3] of a batch (the box scene's grid layout, 0.25 m between beds)."""
    from gmloco.eval.mpm.box_scene import MpmBoxSceneCfg, region_offsets

    return region_offsets(MpmBoxSceneCfg(bed=cfg.bed), count)


def run_plate_intrusion(
    cfg: PlateIntrusionCfg, material: GranularMaterial | MpmMaterialCfg, normal: np.ndarray, velocity: np.ndarray
) -> PlateRun:
    """Push one plate through a fresh bed at constant velocity and log the sand force per frame.

    Args:
        cfg: Plate, bed and numerics.
        material: The medium (mapped through :func:`mpm_material`).
        normal: Plate normal [-], [3].
        velocity: Plate velocity [m/s], [3] (its magnitude is replaced by ``cfg.speed``).
    """
    return run_plate_intrusions(cfg, material, [(normal, velocity)])[0]


def run_plate_intrusions(
    cfg: PlateIntrusionCfg, material: GranularMaterial | MpmMaterialCfg, directions: list[tuple[np.ndarray, np.ndarray]]
) -> list[PlateRun]:
    """Push several plates, each through its own walled bed, in one MPM solve; log each plate's force per frame.

    Every plate moves at constant velocity for its own path duration and then holds still until the longest path
    ends (frames after its path are not sampled). ``wall_time`` of each run is the batch's, divided by its size.

    Args:
        cfg: Plate, bed and numerics (one region's bed).
        material: The medium (mapped through :func:`mpm_material`).
        directions: (plate normal [3], velocity [3]) per run (velocity magnitudes are replaced by ``cfg.speed``).
    """
    import newton
    import warp as wp

    from gmloco.eval.mpm.kernels_coupling import eval_body_sand_wrench

    t0 = time.perf_counter()
    mat = material if isinstance(material, MpmMaterialCfg) else mpm_material(material)
    friction = mat.collider_friction if cfg.plate_friction is None else cfg.plate_friction
    offsets = _plate_offsets(cfg, len(directions))
    vels = [cfg.speed * np.asarray(v, dtype=np.float64) / np.linalg.norm(v) for _, v in directions]
    paths = [plate_path(cfg, v) for v in vels]
    starts = [start + off for (start, _), off in zip(paths, offsets, strict=True)]
    rots = [plate_rotation(n) for n, _ in directions]
    quats = [_quat_xyzw(r) for r in rots]
    half = 0.5 * np.array([cfg.plate_size, cfg.plate_size, cfg.plate_thickness])
    s = cfg.solver
    num_frames = max(math.ceil(duration / s.frame_dt) for _, duration in paths)
    with wp.ScopedDevice(wp.get_device(cfg.device)):
        colliders, bodies = _build_colliders(newton, wp, cfg, list(zip(starts, rots, strict=True)), offsets,
                                             friction, mat)  # fmt: skip

        def outside_plates(p: np.ndarray) -> np.ndarray:
            """Carve each plate's start volume (plus half a voxel) out of the bed."""
            keep = np.ones(len(p), dtype=bool)
            for start, rot in zip(starts, rots, strict=True):
                keep &= np.any(np.abs((p - start) @ rot) > half + 0.5 * s.voxel_size, axis=1)
            return keep

        sand = newton.ModelBuilder()
        newton.solvers.SolverImplicitMPM.register_custom_attributes(sand)
        count = 0
        for i, off in enumerate(offsets):
            bed = replace(cfg.bed, center_x=cfg.bed.center_x + off[0], center_y=cfg.bed.center_y + off[1],
                          seed=cfg.bed.seed + i)  # fmt: skip
            count += emit_bed_particles(sand, bed, s.voxel_size, mat.density, keep=outside_plates)
        model = sand.finalize()
        apply_mpm_material(model, mat)
        mpm = make_mpm_solver(newton, model, s, mat)
        mpm.setup_collider(model=colliders)  # kinematic bodies -> zero effective mass: prescribed motion
        state = model.state()
        state.body_q = body_q = wp.clone(colliders.body_q)
        state.body_qd = body_qd = wp.zeros(colliders.body_count, dtype=wp.spatial_vectorf)
        wrench = wp.zeros(colliders.body_count, dtype=wp.spatial_vectorf)
        depth, force = np.zeros((len(bodies), num_frames)), np.zeros((len(bodies), num_frames, 3))
        t_loop = time.perf_counter()
        for k in range(num_frames):
            q_np, qd_np = _plate_poses(colliders.body_count, bodies, starts, quats, vels, paths, k, s.frame_dt)
            body_q.assign(q_np)
            body_qd.assign(qd_np)
            # Newton annotates control/contacts as required, but SolverImplicitMPM.step documents both as unused
            mpm.step(state, state, None, None, s.frame_dt)  # pyright: ignore[reportArgumentType]
            eval_body_sand_wrench(mpm.collider_body_index, colliders.body_com, s.frame_dt,
                                  mpm.collect_collider_impulses(state), body_q, wrench)  # fmt: skip
            force[:, k] = wrench.numpy()[bodies][:, :3]
            depth[:, k] = -(q_np[bodies, 2] + 0.5 * qd_np[bodies, 2] * s.frame_dt)  # centroid depth at mid-step
        loop_s = time.perf_counter() - t_loop
        mpm.check_sparse_grid_rebuild_status()  # raises if the sparse grid ran out of capacity
    wall = (time.perf_counter() - t0) / len(bodies)
    runs = []
    for i, ((n, _), v, (_, duration)) in enumerate(zip(directions, vels, paths, strict=True)):
        frames = np.arange(1, num_frames + 1)
        travelled = cfg.speed * s.frame_dt * np.minimum(frames, math.ceil(duration / s.frame_dt))
        d_lo, d_hi = cfg.depth_range
        moving = frames * s.frame_dt <= duration + 1e-9
        sampled = (
            moving & (travelled >= cfg.travel_before_sampling) & (depth[i] >= d_lo - 1e-9) & (depth[i] <= d_hi + 1e-9)
        )
        runs.append(PlateRun(np.asarray(n, dtype=np.float64), v, depth[i], force[i], sampled, count // len(bodies),
                             wall, num_frames / max(loop_s, 1e-9)))  # fmt: skip
    return runs


def _plate_poses(
    body_count: int, bodies: list[int], starts: list[np.ndarray], quats: list[tuple[float, ...]],
    vels: list[np.ndarray], paths: list[tuple[np.ndarray, float]], k: int, dt: float,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Body poses [B, 7] (p, q_xyzw) and velocities [B, 6] of frame ``k``: moving along the path, then at rest."""
    q = np.zeros((body_count, 7), dtype=np.float32)
    qd = np.zeros((body_count, 6), dtype=np.float32)
    for b, start, quat, v, (_, duration) in zip(bodies, starts, quats, vels, paths, strict=True):
        moving = (k + 1) * dt <= duration + 1e-9
        t = min(k * dt, duration)
        q[b, :3], q[b, 3:] = start + v * t, quat
        qd[b, :3] = v if moving else 0.0
    return q, qd


def _quat_xyzw(rot: np.ndarray) -> tuple[float, float, float, float]:
    """Unit quaternion (x, y, z, w) of a rotation matrix."""
    import warp as wp

    # Warp's stubs do not relate the concrete ``mat33`` class to the ``Matrix[Float, 3, 3]`` overload
    qq = wp.quat_from_matrix(wp.mat33(*rot.ravel().tolist()))  # pyright: ignore[reportCallIssue, reportArgumentType]
    return (float(qq[0]), float(qq[1]), float(qq[2]), float(qq[3]))
