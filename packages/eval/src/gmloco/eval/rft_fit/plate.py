# SPDX-License-Identifier: Apache-2.0
"""MPM plate intrusion at constant velocity: a kinematic thin plate dragged through a sand bed.

The plate is a zero-mass (kinematic) collider body of Newton's implicit MPM; its pose and velocity are
prescribed each frame and the force of the sand is the sum of its collider-node impulses / dt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from gmloco.eval.mpm.bed import SandBedCfg, add_bed_container, emit_sand_bed
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.materials import GranularMaterial, MpmMaterialCfg, apply_mpm_material, mpm_material

__all__ = ["PLATE_MASS", "PlateIntrusionCfg", "PlateRun", "plate_rotation", "run_plate_intrusion"]

PLATE_MASS = 1.0e6
"""Effective collider mass of the prescribed-motion plate [kg]."""


@dataclass(frozen=True)
class PlateIntrusionCfg:
    """One family of constant-velocity plate intrusions (geometry and numerics; direction per run)."""

    plate_size: float = 0.1
    """Square plate edge L [m]."""
    plate_thickness: float = 0.01
    """Plate thickness [m]."""
    speed: float = 0.2
    """Intrusion speed [m/s] (quasi-static: inertial stress rho v^2 << rho g d)."""
    depth_range: tuple[float, float] = (0.08, 0.2)
    """Centroid depths [m] at which steady stresses are sampled."""
    travel_before_sampling: float = 0.1
    """Distance the plate moves before samples count (leaves the carved start cavity) [m]."""
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
    """Wall-clock time of the run [s]."""


def plate_rotation(normal: np.ndarray) -> np.ndarray:
    """Return a rotation matrix whose local z axis is ``normal`` [3, 3]."""
    z = np.asarray(normal, dtype=np.float64) / np.linalg.norm(normal)
    ref = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(ref, z)
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z], axis=1)


def _path(cfg: PlateIntrusionCfg, velocity: np.ndarray) -> tuple[np.ndarray, float]:
    """Start position [m] and duration [s] so that the sampled part of the path spans the depth range."""
    v_hat = velocity / np.linalg.norm(velocity)
    d_lo, d_hi = cfg.depth_range
    vz = v_hat[2]
    if abs(vz) > 1e-3:  # vertical component: traverse the depth range, plus the lead-in distance
        span = (d_hi - d_lo) / abs(vz)
        d_end = d_hi if vz < 0 else d_lo
        end = np.array([0.0, 0.0, -d_end])
        length = span + cfg.travel_before_sampling
    else:  # horizontal: constant mid depth
        end = np.array([0.0, 0.0, -0.5 * (d_lo + d_hi)])
        length = cfg.travel_before_sampling + 2.0 * cfg.plate_size
    start = end - v_hat * length
    centre = start + 0.5 * v_hat * length
    start[:2] -= centre[:2]  # centre the path horizontally in the bed
    return start, length / cfg.speed


def run_plate_intrusion(
    cfg: PlateIntrusionCfg, material: GranularMaterial | MpmMaterialCfg, normal: np.ndarray, velocity: np.ndarray
) -> PlateRun:
    """Drag one plate through a fresh bed and log the sand force per frame.

    Args:
        cfg: Plate, bed and numerics.
        material: The medium (mapped through :func:`mpm_material`).
        normal: Plate normal [-], [3].
        velocity: Plate velocity [m/s], [3] (its magnitude is replaced by ``cfg.speed``).
    """
    import time

    import newton
    import warp as wp

    from gmloco.eval.mpm.kernels_coupling import eval_body_sand_wrench

    mat = material if isinstance(material, MpmMaterialCfg) else mpm_material(material)
    v = np.asarray(velocity, dtype=np.float64)
    v = cfg.speed * v / np.linalg.norm(v)
    start, duration = _path(cfg, v)
    rot = plate_rotation(normal)
    half = np.array([0.5 * cfg.plate_size, 0.5 * cfg.plate_size, 0.5 * cfg.plate_thickness])
    t0 = time.perf_counter()
    device = wp.get_device(cfg.device)
    with wp.ScopedDevice(device):
        # colliders (plate + container) in their own model, as in the box scene; particles in the sand model
        rigid = newton.ModelBuilder()
        q = _quat_xyzw(rot)
        body = rigid.add_body(xform=wp.transform(wp.vec3(*start.tolist()), wp.quat(*q)), mass=1.0, is_kinematic=True)
        rigid.add_shape_box(body, hx=float(half[0]), hy=float(half[1]), hz=float(half[2]),
                            cfg=newton.ModelBuilder.ShapeConfig(density=0.0, mu=float(mat.collider_friction)))  # fmt: skip
        add_bed_container(rigid, cfg.bed, friction=mat.friction)
        rigid_model = rigid.finalize()

        def outside_plate(p: np.ndarray) -> np.ndarray:
            local = (p - start) @ rot
            return np.any(np.abs(local) > half + 0.5 * cfg.solver.voxel_size, axis=1)

        sand = newton.ModelBuilder()
        newton.solvers.SolverImplicitMPM.register_custom_attributes(sand)
        count = emit_sand_bed(sand, cfg.bed, cfg.solver.voxel_size, mat.density, keep=outside_plate)
        model = sand.finalize()
        apply_mpm_material(model, mat)
        s = cfg.solver
        mpm = newton.solvers.SolverImplicitMPM(model, config=newton.solvers.SolverImplicitMPM.Config(
            voxel_size=s.voxel_size, max_iterations=s.max_iterations, tolerance=s.tolerance, grid_type=s.grid_type,
            grid_padding=s.grid_padding, max_active_cell_count=s.max_active_cell_count, strain_basis=s.strain_basis,
            critical_fraction=mat.critical_fraction))  # fmt: skip
        # a very heavy (1e6 kg) compliant collider: its prescribed motion is unaffected by the sand, and unlike a
        # zero-mass kinematic collider its contact impulses are reported (zero-mass colliders reported none here)
        mpm.setup_collider(model=rigid_model, body_mass=wp.full(rigid_model.body_count, PLATE_MASS, dtype=float))
        state = model.state()
        rigid_state = rigid_model.state()
        body_q, body_qd, body_com = rigid_state.body_q, rigid_state.body_qd, rigid_model.body_com
        if body_q is None or body_qd is None or body_com is None:
            raise RuntimeError("the collider model has no body arrays")  # Newton allocates them: it holds the plate
        state.body_q, state.body_qd = body_q, body_qd
        # wp.spatial_vectorf is wp.spatial_vector; Warp's stubs type only the former as a dtype class
        wrench = wp.zeros(rigid_model.body_count, dtype=wp.spatial_vectorf)
        num_frames = math.ceil(duration / s.frame_dt)
        depth, force = np.zeros(num_frames), np.zeros((num_frames, 3))
        qd = wp.array([[*v.tolist(), 0.0, 0.0, 0.0]], dtype=wp.spatial_vectorf)
        for k in range(num_frames):
            p = start + v * k * s.frame_dt
            body_q.assign([wp.transform(wp.vec3(*p.tolist()), wp.quat(*q))])
            wp.copy(body_qd, qd)
            # Newton annotates control/contacts as required, but SolverImplicitMPM.step documents both as unused
            mpm.step(state, state, None, None, s.frame_dt)  # pyright: ignore[reportArgumentType]
            eval_body_sand_wrench(mpm.collider_body_index, body_com, s.frame_dt,
                                  mpm.collect_collider_impulses(state), body_q, wrench)  # fmt: skip
            force[k] = wrench.numpy()[body][:3]
            depth[k] = -(p + 0.5 * v * s.frame_dt)[2]  # centroid depth at mid-step
    travelled = cfg.speed * s.frame_dt * np.arange(1, num_frames + 1)
    d_lo, d_hi = cfg.depth_range
    sampled = (travelled >= cfg.travel_before_sampling) & (depth >= d_lo - 1e-9) & (depth <= d_hi + 1e-9)
    return PlateRun(np.asarray(normal, dtype=np.float64), v, depth, force, sampled, count, time.perf_counter() - t0)


def _quat_xyzw(rot: np.ndarray) -> tuple[float, float, float, float]:
    """Unit quaternion (x, y, z, w) of a rotation matrix."""
    import warp as wp

    # Warp's stubs do not relate the concrete ``mat33`` class to the ``Matrix[Float, 3, 3]`` overload
    qq = wp.quat_from_matrix(wp.mat33(*rot.ravel().tolist()))  # pyright: ignore[reportCallIssue, reportArgumentType]
    return (float(qq[0]), float(qq[1]), float(qq[2]), float(qq[3]))
