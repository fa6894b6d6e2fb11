# SPDX-License-Identifier: Apache-2.0
"""Warp kernels of the moving sand window: window pose from the robot, column allocation and recycling, walls.

The sand lies in world columns (I, J) of width h = voxel_size / particles_per_voxel (column centre
((I + 0.5) h, (J + 0.5) h) in lane coordinates); a column holds nz particles from the floor z = -depth to the
terrain surface z_s(x, y), each of volume h^2 hz with hz = (z_s + depth) / nz. A robot's window is the rectangle
nx h x ny h centred at ((I0 + nx / 2) h, (J0 + ny / 2) h) and turned by the window heading psi_w: it holds exactly
the world columns whose centre lies inside it. The origin (I0, J0) follows the pelvis (``lead`` ahead of it along
its heading, in whole columns); psi_w follows the robot's heading, updated when the two differ by more than
``turn_step`` (0 when the window keeps the grid's axes).

Particle layout (set by :class:`gmloco.eval.mpm.window.SandWindow`): robot r owns ``slots`` slot columns of nz
particles, particle p = (r slots + s) nz + k. Every frame :func:`eval_window_allocate` frees the slots whose
column left the rectangle and gives the freed slots to the columns that entered it (one thread per robot, a
serial sweep of its slots and of a grid x grid patch of columns around the window: no atomics, deterministic);
:func:`eval_window_recycle` then re-seeds the particles of every slot whose column changed (fresh, stress-free
sand of the terrain there) and parks those of a slot left free: ACTIVE flag cleared and material volume zeroed in
place, as a retired lane's are, so the MPM solve skips them. ``slots`` bounds the columns a turned rectangle can
hold (``window_slots``), so every column inside the window has sand. With psi_w = 0 and ``slots = nx ny`` the
window is the axis-aligned box [I0, I0 + nx) x [J0, J0 + ny) of columns.
"""

from __future__ import annotations

import warp as wp

__all__ = [
    "FREE_COLUMN",
    "WindowArrays",
    "eval_window_allocate",
    "eval_window_origin",
    "eval_window_recycle",
    "eval_window_wall_pose",
    "eval_window_walls",
]

FREE_COLUMN = wp.constant(-(2**30))
"""Column index of a free slot (no column) and of a particle not seeded yet."""


@wp.struct
class WindowArrays:
    """Window geometry and terrain (model side, constant over a run)."""

    nx: int
    """Columns along x per robot."""
    ny: int
    """Columns along y per robot."""
    nz: int
    """Particles per column."""
    slots: int
    """Slot columns per robot (>= the columns a turned window holds)."""
    grid: int
    """Side of the patch of columns swept around a window by the allocation (covers its turned extent)."""
    turn: int
    """1: the window turns with the robot's heading; 0: it keeps the grid's axes."""
    turn_step: float
    """Heading change of the robot that turns the window to it [rad]."""
    active_flag: int
    """Newton's ``ParticleFlags.ACTIVE`` bit."""
    lane_active: wp.array[int]
    """1 while a lane's sand is in the solve, 0 once retired, [R] (a re-seeded slot of a retired lane stays out)."""
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
def window_centre(w: WindowArrays, o: wp.vec2i) -> wp.vec2:
    """Window centre ((I0 + nx / 2) h, (J0 + ny / 2) h) in lane coordinates [m]."""
    return wp.vec2((float(o[0]) + 0.5 * float(w.nx)) * w.h, (float(o[1]) + 0.5 * float(w.ny)) * w.h)


@wp.func
def window_local(centre: wp.vec2, psi: float, x: float, y: float) -> wp.vec2:
    """(u, v): a lane-coordinate point in the window frame (u along psi_w) [m]."""
    dx = x - centre[0]
    dy = y - centre[1]
    c = wp.cos(psi)
    s = wp.sin(psi)
    return wp.vec2(c * dx + s * dy, -s * dx + c * dy)


@wp.func
def window_holds(w: WindowArrays, centre: wp.vec2, psi: float, col: wp.vec2i) -> bool:
    """Whether column ``col``'s centre lies strictly inside the window rectangle."""
    if col[0] == FREE_COLUMN:
        return False
    uv = window_local(centre, psi, (float(col[0]) + 0.5) * w.h, (float(col[1]) + 0.5) * w.h)
    return wp.abs(uv[0]) < 0.5 * float(w.nx) * w.h and wp.abs(uv[1]) < 0.5 * float(w.ny) * w.h


@wp.func
def wrap_angle(a: float) -> float:
    """Angle wrapped to [-pi, pi) [rad]."""
    return a - 2.0 * wp.pi * wp.floor((a + wp.pi) / (2.0 * wp.pi))


@wp.kernel
def _window_origin(
    # Model:
    w: WindowArrays,
    track: int,
    # Data in:
    body_q_in: wp.array[wp.transform],
    # Data out:
    origin_out: wp.array[wp.vec2i],
    heading_out: wp.array[float],
) -> None:
    """Window origin (I0, J0) and heading psi_w of each robot (when tracking); a NaN heading snaps to the robot's."""
    r = wp.tid()
    psi_w = heading_out[r]
    if track == 0:
        if wp.isnan(psi_w):
            heading_out[r] = 0.0
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
    if w.turn == 0:
        heading_out[r] = 0.0
        return
    psi = wp.atan2(heading[1], heading[0])
    if wp.isnan(psi_w) or wp.abs(wrap_angle(psi - psi_w)) > w.turn_step:
        heading_out[r] = psi


def eval_window_origin(
    w: WindowArrays, track: bool, body_q: wp.array, origin_out: wp.array, heading_out: wp.array
) -> None:
    """Write each robot's window origin (column indices) and heading from the pelvis pose (when tracking)."""
    wp.launch(_window_origin, dim=origin_out.shape[0], inputs=[w, int(track), body_q],
              outputs=[origin_out, heading_out], device=origin_out.device)  # fmt: skip


@wp.kernel
def _window_allocate(
    # Model:
    w: WindowArrays,
    # Data in:
    origin_in: wp.array[wp.vec2i],
    heading_in: wp.array[float],
    # Data out:
    slot_column_out: wp.array[wp.vec2i],
    free_slot_out: wp.array[int],
    occupied_out: wp.array[int],
) -> None:
    """Free the slots whose column left robot r's window; give them to the window's columns that have none."""
    r = wp.tid()
    o = origin_in[r]
    psi = heading_in[r]
    centre = window_centre(w, o)
    g = w.grid
    bi = o[0] + w.nx / 2 - g / 2
    bj = o[1] + w.ny / 2 - g / 2
    for q in range(g * g):
        occupied_out[r * g * g + q] = 0
    nfree = wp.int32(0)
    for s in range(w.slots):
        col = slot_column_out[r * w.slots + s]
        if window_holds(w, centre, psi, col):
            occupied_out[r * g * g + (col[0] - bi) * g + (col[1] - bj)] = 1
        else:
            slot_column_out[r * w.slots + s] = wp.vec2i(FREE_COLUMN, FREE_COLUMN)
            free_slot_out[r * w.slots + nfree] = s
            nfree += 1
    k = wp.int32(0)
    for a in range(g):
        for b in range(g):
            col = wp.vec2i(bi + a, bj + b)
            if k < nfree and occupied_out[r * g * g + a * g + b] == 0 and window_holds(w, centre, psi, col):
                slot_column_out[r * w.slots + free_slot_out[r * w.slots + k]] = col
                k += 1


def eval_window_allocate(
    w: WindowArrays, origin: wp.array, heading: wp.array, slot_column: wp.array, scratch: tuple
) -> None:
    """Match every robot's slot columns to the columns inside its window (one thread per robot).

    Args:
        w: Window geometry and terrain.
        origin: Window origin (I0, J0) per robot, [R].
        heading: Window heading psi_w per robot [rad], [R].
        slot_column: World column of every slot (``FREE_COLUMN``: none), [R slots]; updated.
        scratch: (free-slot list [R slots], column occupancy [R grid^2]) int arrays.
    """
    wp.launch(_window_allocate, dim=origin.shape[0], inputs=[w, origin, heading],
              outputs=[slot_column, *scratch], device=origin.device)  # fmt: skip


@wp.kernel
def _window_recycle(
    # Model:
    w: WindowArrays,
    # Data in:
    origin_in: wp.array[wp.vec2i],
    heading_in: wp.array[float],
    slot_column_in: wp.array[wp.vec2i],
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
    flags_out: wp.array[wp.int32],
    transfer_flags_out: wp.array[wp.int32],
    material_flags_out: wp.array[wp.int32],
) -> None:
    """Re-seed every particle whose slot now holds another column (fresh terrain sand); park those of free slots."""
    p = wp.tid()
    n = w.slots * w.nz
    r = p / n
    loc = p - r * n
    k = loc % w.nz
    slot = loc / w.nz
    col = slot_column_in[r * w.slots + slot]
    if col[0] == column_out[p][0] and col[1] == column_out[p][1]:
        return
    column_out[p] = col
    bit = wp.int32(w.active_flag)
    if col[0] == FREE_COLUMN:  # parked: out of the solve until its slot takes a column again
        flags_out[p] = flags_out[p] & ~bit
        transfer_flags_out[p] = transfer_flags_out[p] & ~bit
        material_flags_out[p] = material_flags_out[p] & ~bit
        material_volume_out[p] = 0.0
        particle_qd_out[p] = wp.vec3(0.0)
        return
    # a fresh, cell-centred, jittered lattice position in the new column, kept inside the window (the jitter
    # depends on the column, so a column re-entering the window gets new grains)
    rng = wp.rand_init(w.seed + w.lane_seed[r] * 15485863, p * 7919 + col[0] * 104729 + col[1] * 1299709)
    x = (float(col[0]) + 0.5 + w.jitter * (wp.randf(rng) - 0.5)) * w.h
    y_lane = (float(col[1]) + 0.5 + w.jitter * (wp.randf(rng) - 0.5)) * w.h
    centre = window_centre(w, origin_in[r])
    psi = heading_in[r]
    uv = window_local(centre, psi, x, y_lane)
    hu = 0.5 * float(w.nx) * w.h
    hv = 0.5 * float(w.ny) * w.h
    uc = wp.clamp(uv[0], -hu, hu)
    vc = wp.clamp(uv[1], -hv, hv)
    c = wp.cos(psi)
    s = wp.sin(psi)
    x = centre[0] + c * uc - s * vc
    y_lane = centre[1] + s * uc + c * vc
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
    if w.lane_active[r] != 0:  # a retired lane's re-seeded sand stays out of the solve
        flags_out[p] = flags_out[p] | bit
        transfer_flags_out[p] = transfer_flags_out[p] | bit
        material_flags_out[p] = material_flags_out[p] | bit
        material_volume_out[p] = vol
    else:
        material_volume_out[p] = 0.0


def eval_window_recycle(
    w: WindowArrays,
    origin: wp.array,
    heading: wp.array,
    slot_column: wp.array,
    column: wp.array,
    state_arrays: tuple,
    model_arrays: tuple,
) -> None:
    """Re-seed the particles of the slots whose column changed; park the particles of free slots.

    Args:
        w: Window geometry and terrain.
        origin: Window origin (I0, J0) per robot, [R].
        heading: Window heading psi_w per robot [rad], [R].
        slot_column: World column of every slot (``eval_window_allocate``), [R slots].
        column: World column each particle currently stands for, [P]; updated.
        state_arrays: (particle_q [m], particle_qd [m/s], qd_grad, elastic_strain, Jp, stress, transform), [P].
        model_arrays: (particle_mass [kg], particle_radius [m], mpm friction, MPM's cached particle volume
            [m^3], density [kg/m^3] and material volume [m^3], the model's particle flags, MPM's transfer and
            material flags), [P].
    """
    wp.launch(_window_recycle, dim=column.shape[0], inputs=[w, origin, heading, slot_column],
              outputs=[column, *state_arrays, *model_arrays], device=column.device)  # fmt: skip


@wp.kernel
def _window_walls(
    # Model:
    w: WindowArrays,
    # Data in:
    origin_in: wp.array[wp.vec2i],
    heading_in: wp.array[float],
    # Data out:
    particle_q_out: wp.array[wp.vec3],
    particle_qd_out: wp.array[wp.vec3],
) -> None:
    """Frictionless side walls on the window boundary: clamp the position, drop the outward velocity (window frame)."""
    p = wp.tid()
    r = p / (w.slots * w.nz)
    centre = window_centre(w, origin_in[r]) + wp.vec2(0.0, w.lane_y[r])
    psi = heading_in[r]
    c = wp.cos(psi)
    s = wp.sin(psi)
    q = particle_q_out[p]
    v = particle_qd_out[p]
    uv = window_local(centre, psi, q[0], q[1])
    vel = wp.vec2(c * v[0] + s * v[1], -s * v[0] + c * v[1])
    half = wp.vec2(0.5 * float(w.nx) * w.h, 0.5 * float(w.ny) * w.h)
    moved = wp.int32(0)
    for a in range(2):
        if uv[a] < -half[a]:
            uv[a] = -half[a]
            vel[a] = wp.max(vel[a], 0.0)
            moved = 1
        if uv[a] > half[a]:
            uv[a] = half[a]
            vel[a] = wp.min(vel[a], 0.0)
            moved = 1
    if moved == 0:
        return
    particle_q_out[p] = wp.vec3(centre[0] + c * uv[0] - s * uv[1], centre[1] + s * uv[0] + c * uv[1], q[2])
    particle_qd_out[p] = wp.vec3(c * vel[0] - s * vel[1], s * vel[0] + c * vel[1], v[2])


def eval_window_walls(
    w: WindowArrays, origin: wp.array, heading: wp.array, particle_q: wp.array, particle_qd: wp.array
) -> None:
    """Keep every robot's sand inside its window rectangle (frictionless walls that move with the window)."""
    wp.launch(_window_walls, dim=particle_q.shape[0], inputs=[w, origin, heading], outputs=[particle_q, particle_qd],
              device=particle_q.device)  # fmt: skip


@wp.kernel
def _window_wall_pose(
    # Model:
    w: WindowArrays,
    body_offset: int,
    # Data in:
    origin_in: wp.array[wp.vec2i],
    heading_in: wp.array[float],
    # Data out:
    body_q_out: wp.array[wp.transform],
    body_qd_out: wp.array[wp.spatial_vector],
) -> None:
    """Pose of robot r's wall body: the window centre (x, y) at z = 0, turned by psi_w about z, at rest."""
    r = wp.tid()
    centre = window_centre(w, origin_in[r])
    p = wp.vec3(centre[0], centre[1] + w.lane_y[r], 0.0)
    body_q_out[body_offset + r] = wp.transform(p, wp.quat_from_axis_angle(wp.vec3(0.0, 0.0, 1.0), heading_in[r]))
    body_qd_out[body_offset + r] = wp.spatial_vector()


def eval_window_wall_pose(
    w: WindowArrays, origin: wp.array, heading: wp.array, body_offset: int, body_q: wp.array, body_qd: wp.array
) -> None:
    """Move every robot's wall collider body (index ``body_offset + r``) to its window (graph-capturable).

    The walls are kinematic MPM colliders (zero effective mass) whose boxes sit on the window boundary in the
    body frame; they jump with the window origin by whole columns and with its heading by ``turn_step``, after the
    columns they leave were parked, so their velocity is zero.
    """
    wp.launch(_window_wall_pose, dim=origin.shape[0], inputs=[w, body_offset, origin, heading],
              outputs=[body_q, body_qd], device=body_q.device)  # fmt: skip
