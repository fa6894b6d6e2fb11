# SPDX-License-Identifier: Apache-2.0
"""Warp kernels of the moving sand window: window origin from the robot, column recycling, window walls.

Particle layout (set by :class:`gmloco.eval.mpm.window.SandWindow`): robot r owns particles
[r n, (r + 1) n), n = nx ny nz; local index l = (i ny + j) nz + k holds lattice slot (i, j, k). Slot column
(i, j) stands for the world column (I, J) with I = I0 + ((i - I0) mod nx), J likewise: a torus over the window,
so when the window origin (I0, J0) advances by one column, exactly the slots of the column left behind are
re-seeded in the column that enters at the front (fresh, stress-free sand of the terrain at that place).
Columns are h = voxel_size / particles_per_voxel wide; a column holds nz particles from the floor
z = -depth to the terrain surface z_s(x, y), each of volume h^2 hz with hz = (z_s + depth) / nz.
"""

from __future__ import annotations

import warp as wp

__all__ = ["WindowArrays", "eval_window_origin", "eval_window_recycle", "eval_window_wall_pose", "eval_window_walls"]


@wp.struct
class WindowArrays:
    """Window geometry and terrain (model side, constant over a run)."""

    nx: int
    """Columns along x per robot."""
    ny: int
    """Columns along y per robot."""
    nz: int
    """Particles per column."""
    h: float
    """Column width [m]."""
    depth: float
    """Sand depth below z = 0 [m]."""
    lead: float
    """Window centre ahead of the pelvis along its heading [m]."""
    offset_y: float
    """Window centre left of the pelvis heading [m]."""
    seed: int
    """Jitter seed."""
    lane_seed: wp.array[int]
    """Jitter seed offset of each robot's current episode (0 for the first), [R]: a refilled lane gets new grains."""
    jitter: float
    """Jitter as a fraction of the spacing [-]."""
    bodies_per_robot: int
    """Rigid bodies per robot (pelvis = first body of each robot)."""
    lane_y: wp.array[float]
    """Lane offset of each robot along y [m], [R]."""
    rough_amplitude: float
    """Sinusoid amplitude [m]."""
    rough_k: float
    """Sinusoid wavenumber 2 pi / lambda [1/m]."""
    layer_start: float
    """Course x from which layers are counted [m]."""
    layer_length: float
    """Layer length [m]."""
    layer_density: wp.array[float]
    """Particle density of each medium [kg/m^3], [M]."""
    layer_friction: wp.array[float]
    """Drucker-Prager friction of each medium [-], [M]."""


@wp.func
def surface_z(w: WindowArrays, x: float, y_lane: float) -> float:
    """Terrain surface height z_s = A sin(k x) sin(k y) [m] (lane coordinates)."""
    return w.rough_amplitude * wp.sin(w.rough_k * x) * wp.sin(w.rough_k * y_lane)


@wp.func
def layer_index(w: WindowArrays, x: float) -> int:
    """Medium index at course position x: floor((x - start) / length) clipped to [0, M - 1]."""
    k = int(wp.floor((x - w.layer_start) / w.layer_length))
    return wp.clamp(k, 0, w.layer_density.shape[0] - 1)


@wp.func
def torus_column(i: int, origin: int, n: int) -> int:
    """World column of slot column i when the window starts at column ``origin``: origin + ((i - origin) mod n)."""
    m = (i - origin) % n
    if m < 0:
        m += n
    return origin + m


@wp.kernel
def _window_origin(
    # Model:
    w: WindowArrays,
    track: int,
    # Data in:
    body_q_in: wp.array[wp.transform],
    # Data out:
    origin_out: wp.array[wp.vec2i],
) -> None:
    """Window origin (I0, J0) of each robot: the window centred ``lead`` ahead of the pelvis (when tracking)."""
    r = wp.tid()
    if track == 0:
        return
    pose = body_q_in[r * w.bodies_per_robot]
    fwd = wp.quat_rotate(wp.transform_get_rotation(pose), wp.vec3(1.0, 0.0, 0.0))
    heading = wp.normalize(wp.vec2(fwd[0], fwd[1]) + wp.vec2(1.0e-9, 0.0))
    p = wp.transform_get_translation(pose)
    cx = p[0] + w.lead * heading[0] - w.offset_y * heading[1]
    cy = p[1] - w.lane_y[r] + w.lead * heading[1] + w.offset_y * heading[0]
    i0 = int(wp.floor(cx / w.h - 0.5 * float(w.nx) + 0.5))
    j0 = int(wp.floor(cy / w.h - 0.5 * float(w.ny) + 0.5))
    origin_out[r] = wp.vec2i(i0, j0)


def eval_window_origin(w: WindowArrays, track: bool, body_q: wp.array, origin_out: wp.array) -> None:
    """Write each robot's window origin (column indices) from the pelvis pose; a no-op when not tracking."""
    wp.launch(_window_origin, dim=origin_out.shape[0], inputs=[w, int(track), body_q], outputs=[origin_out],
              device=origin_out.device)  # fmt: skip


@wp.kernel
def _window_recycle(
    # Model:
    w: WindowArrays,
    # Data in:
    origin_in: wp.array[wp.vec2i],
    # Data out:
    column_out: wp.array[wp.vec2i],
    particle_q_out: wp.array[wp.vec3],
    particle_qd_out: wp.array[wp.vec3],
    qd_grad_out: wp.array[wp.mat33],
    elastic_strain_out: wp.array[wp.mat33],
    jp_out: wp.array[float],
    stress_out: wp.array[wp.mat33],
    transform_out: wp.array[wp.mat33],
    particle_mass_out: wp.array[float],
    particle_radius_out: wp.array[float],
    friction_out: wp.array[float],
    volume_out: wp.array[float],
    density_out: wp.array[float],
    material_volume_out: wp.array[float],
) -> None:
    """Re-seed every particle whose slot column now stands for another world column (fresh terrain sand)."""
    p = wp.tid()
    n = w.nx * w.ny * w.nz
    r = p / n
    loc = p - r * n
    k = loc % w.nz
    c = loc / w.nz
    i = c / w.ny
    j = c - i * w.ny
    o = origin_in[r]
    col = wp.vec2i(torus_column(i, o[0], w.nx), torus_column(j, o[1], w.ny))
    if col[0] == column_out[p][0] and col[1] == column_out[p][1]:
        return
    column_out[p] = col
    # a fresh, cell-centred, jittered lattice position in the new column (the jitter depends on the column,
    # so a column re-entering the window gets new grains)
    rng = wp.rand_init(w.seed + w.lane_seed[r] * 15485863, p * 7919 + col[0] * 104729 + col[1] * 1299709)
    x = (float(col[0]) + 0.5 + w.jitter * (wp.randf(rng) - 0.5)) * w.h
    y_lane = (float(col[1]) + 0.5 + w.jitter * (wp.randf(rng) - 0.5)) * w.h
    hz = (surface_z(w, x, y_lane) + w.depth) / float(w.nz)
    z = -w.depth + (float(k) + 0.5 + w.jitter * (wp.randf(rng) - 0.5)) * hz
    particle_q_out[p] = wp.vec3(x, y_lane + w.lane_y[r], z)
    particle_qd_out[p] = wp.vec3(0.0)
    # stress-free, undeformed (Newton's registered defaults)
    qd_grad_out[p] = wp.mat33(0.0)
    elastic_strain_out[p] = wp.identity(3, float)
    jp_out[p] = 1.0
    stress_out[p] = wp.mat33(0.0)
    transform_out[p] = wp.identity(3, float)
    # medium at x: volume h^2 hz (Newton: V = 8 r^3), mass rho_c V, friction mu_int
    m = layer_index(w, x)
    vol = w.h * w.h * hz
    rho = w.layer_density[m]
    particle_mass_out[p] = rho * vol
    particle_radius_out[p] = 0.5 * wp.pow(vol, 1.0 / 3.0)
    friction_out[p] = w.layer_friction[m]
    volume_out[p] = vol
    density_out[p] = rho
    material_volume_out[p] = vol


def eval_window_recycle(
    w: WindowArrays,
    origin: wp.array,
    column: wp.array,
    state_arrays: tuple,
    model_arrays: tuple,
) -> None:
    """Re-seed the particles of the columns that left the window, in the columns that entered it.

    Args:
        w: Window geometry and terrain.
        origin: Window origin (I0, J0) per robot, [R].
        column: World column (I, J) each particle currently stands for, [P]; updated.
        state_arrays: (particle_q [m], particle_qd [m/s], qd_grad, elastic_strain, Jp, stress, transform), [P].
        model_arrays: (particle_mass [kg], particle_radius [m], mpm friction, MPM's cached particle volume
            [m^3], density [kg/m^3] and material volume [m^3]), [P].
    """
    wp.launch(_window_recycle, dim=column.shape[0], inputs=[w, origin],
              outputs=[column, *state_arrays, *model_arrays], device=column.device)  # fmt: skip


@wp.kernel
def _window_walls(
    # Model:
    w: WindowArrays,
    # Data in:
    origin_in: wp.array[wp.vec2i],
    # Data out:
    particle_q_out: wp.array[wp.vec3],
    particle_qd_out: wp.array[wp.vec3],
) -> None:
    """Frictionless side walls on the window boundary: clamp the position, drop the outward velocity."""
    p = wp.tid()
    r = p / (w.nx * w.ny * w.nz)
    o = origin_in[r]
    lo = wp.vec2(float(o[0]) * w.h, float(o[1]) * w.h + w.lane_y[r])
    hi = wp.vec2(float(o[0] + w.nx) * w.h, float(o[1] + w.ny) * w.h + w.lane_y[r])
    q = particle_q_out[p]
    v = particle_qd_out[p]
    for a in range(2):
        if q[a] < lo[a]:
            q[a] = lo[a]
            v[a] = wp.max(v[a], 0.0)
        if q[a] > hi[a]:
            q[a] = hi[a]
            v[a] = wp.min(v[a], 0.0)
    particle_q_out[p] = q
    particle_qd_out[p] = v


def eval_window_walls(w: WindowArrays, origin: wp.array, particle_q: wp.array, particle_qd: wp.array) -> None:
    """Keep every robot's sand inside its window box (frictionless walls that move with the window)."""
    wp.launch(_window_walls, dim=particle_q.shape[0], inputs=[w, origin], outputs=[particle_q, particle_qd],
              device=particle_q.device)  # fmt: skip


@wp.kernel
def _window_wall_pose(
    # Model:
    w: WindowArrays,
    body_offset: int,
    # Data in:
    origin_in: wp.array[wp.vec2i],
    # Data out:
    body_q_out: wp.array[wp.transform],
    body_qd_out: wp.array[wp.spatial_vector],
) -> None:
    """Pose of robot r's wall body: the lower window corner (x, y) at z = 0, axis-aligned, at rest."""
    r = wp.tid()
    o = origin_in[r]
    p = wp.vec3(float(o[0]) * w.h, float(o[1]) * w.h + w.lane_y[r], 0.0)
    body_q_out[body_offset + r] = wp.transform(p, wp.quat_identity())
    body_qd_out[body_offset + r] = wp.spatial_vector()


def eval_window_wall_pose(
    w: WindowArrays, origin: wp.array, body_offset: int, body_q: wp.array, body_qd: wp.array
) -> None:
    """Move every robot's wall collider body (index ``body_offset + r``) to its window (graph-capturable).

    The walls are kinematic MPM colliders (zero effective mass) whose boxes sit on the window boundary in the
    body frame; they jump with the window origin by whole columns, after the column they leave was recycled, so
    they never sweep sand: their velocity is zero.
    """
    wp.launch(_window_wall_pose, dim=origin.shape[0], inputs=[w, body_offset, origin], outputs=[body_q, body_qd],
              device=body_q.device)  # fmt: skip
