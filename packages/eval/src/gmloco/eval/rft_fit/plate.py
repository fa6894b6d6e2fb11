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
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gmloco.eval.mpm.bed import SandBedCfg, add_bed_container, emit_sand_bed
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.coupled_setup import make_mpm_solver
from gmloco.eval.mpm.materials import GranularMaterial, MpmMaterialCfg, apply_mpm_material, mpm_material

__all__ = ["PlateIntrusionCfg", "PlateRun", "plate_path", "plate_rotation", "run_plate_intrusion"]


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
    solver: MpmSolverCfg = field(default_factory=lambda: MpmSolverCfg(voxel_size=0.02))
    """MPM numerics."""
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
    """Wall-clock time of the run, construction included [s]."""
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


def _build_colliders(newton: Any, wp: Any, cfg: PlateIntrusionCfg, start: np.ndarray, rot: np.ndarray,
                     friction: float, mat: MpmMaterialCfg) -> tuple[Any, int]:  # fmt: skip
    """Collider model: the kinematic plate body plus the static bed container; return (model, plate body)."""
    builder = newton.ModelBuilder()
    q = _quat_xyzw(rot)
    xform = wp.transform(wp.vec3(*start.tolist()), wp.quat(*q))
    body = builder.add_body(xform=xform, is_kinematic=True, label="plate")
    half = 0.5 * np.array([cfg.plate_size, cfg.plate_size, cfg.plate_thickness])
    shape = newton.ModelBuilder.ShapeConfig(density=0.0, mu=float(friction))
    builder.add_shape_box(body, hx=float(half[0]), hy=float(half[1]), hz=float(half[2]), cfg=shape)
    add_bed_container(builder, cfg.bed, friction=mat.friction)
    return builder.finalize(), body


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
    import newton
    import warp as wp

    from gmloco.eval.mpm.kernels_coupling import eval_body_sand_wrench

    t0 = time.perf_counter()
    mat = material if isinstance(material, MpmMaterialCfg) else mpm_material(material)
    friction = mat.collider_friction if cfg.plate_friction is None else cfg.plate_friction
    v = cfg.speed * np.asarray(velocity, dtype=np.float64) / np.linalg.norm(velocity)
    start, duration = plate_path(cfg, v)
    rot = plate_rotation(normal)
    q = _quat_xyzw(rot)
    half = 0.5 * np.array([cfg.plate_size, cfg.plate_size, cfg.plate_thickness])
    s = cfg.solver
    with wp.ScopedDevice(wp.get_device(cfg.device)):
        colliders, body = _build_colliders(newton, wp, cfg, start, rot, friction, mat)

        def outside_plate(p: np.ndarray) -> np.ndarray:
            """Carve the plate's start volume (plus half a voxel) out of the bed."""
            return np.any(np.abs((p - start) @ rot) > half + 0.5 * s.voxel_size, axis=1)

        sand = newton.ModelBuilder()
        newton.solvers.SolverImplicitMPM.register_custom_attributes(sand)
        count = emit_sand_bed(sand, cfg.bed, s.voxel_size, mat.density, keep=outside_plate)
        model = sand.finalize()
        apply_mpm_material(model, mat)
        mpm = make_mpm_solver(newton, model, s, mat)
        mpm.setup_collider(model=colliders)  # kinematic body -> zero effective mass: prescribed motion
        state = model.state()
        qd = np.zeros((colliders.body_count, 6), dtype=np.float32)
        qd[body, :3] = v
        state.body_q = body_q = wp.clone(colliders.body_q)
        state.body_qd = wp.array(qd, dtype=wp.spatial_vectorf)
        wrench = wp.zeros(colliders.body_count, dtype=wp.spatial_vectorf)
        num_frames = math.ceil(duration / s.frame_dt)
        depth, force = np.zeros(num_frames), np.zeros((num_frames, 3))
        t_loop = time.perf_counter()
        for k in range(num_frames):
            p = start + v * k * s.frame_dt
            body_q.assign([wp.transform(wp.vec3(*p.tolist()), wp.quat(*q))])
            # Newton annotates control/contacts as required, but SolverImplicitMPM.step documents both as unused
            mpm.step(state, state, None, None, s.frame_dt)  # pyright: ignore[reportArgumentType]
            eval_body_sand_wrench(mpm.collider_body_index, colliders.body_com, s.frame_dt,
                                  mpm.collect_collider_impulses(state), body_q, wrench)  # fmt: skip
            force[k] = wrench.numpy()[body][:3]
            depth[k] = -(p + 0.5 * v * s.frame_dt)[2]  # centroid depth at mid-step
        loop_s = time.perf_counter() - t_loop
    travelled = cfg.speed * s.frame_dt * np.arange(1, num_frames + 1)
    d_lo, d_hi = cfg.depth_range
    sampled = (travelled >= cfg.travel_before_sampling) & (depth >= d_lo - 1e-9) & (depth <= d_hi + 1e-9)
    return PlateRun(np.asarray(normal, dtype=np.float64), v, depth, force, sampled, count,
                    time.perf_counter() - t0, num_frames / max(loop_s, 1e-9))  # fmt: skip


def _quat_xyzw(rot: np.ndarray) -> tuple[float, float, float, float]:
    """Unit quaternion (x, y, z, w) of a rotation matrix."""
    import warp as wp

    # Warp's stubs do not relate the concrete ``mat33`` class to the ``Matrix[Float, 3, 3]`` overload
    qq = wp.quat_from_matrix(wp.mat33(*rot.ravel().tolist()))  # pyright: ignore[reportCallIssue, reportArgumentType]
    return (float(qq[0]), float(qq[1]), float(qq[2]), float(qq[3]))
