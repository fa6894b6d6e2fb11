# SPDX-License-Identifier: Apache-2.0
"""Warp kernels shared by all models: foot kinematics, terrain queries, wrench reduction, material scatter and eta."""

from __future__ import annotations

import math
from typing import Any

import warp as wp

from gmloco.contact.materials import DR_RANGES_PAPER, GRAVITY, xi_max, xi_n

__all__ = [
    "TerrainData",
    "element_kinematics",
    "eval_foot_wrench",
    "eval_foot_wrench_tiled",
    "eval_material_eta",
    "eval_scatter_values",
    "foot_inputs_finite",
    "foot_partial_wrench",
    "foot_point_kinematics",
    "media_scaling",
    "point_material",
    "terrain_height",
    "tile_block_dim",
    "write_element",
]

HEIGHT_FLAT = wp.constant(0)
HEIGHT_SINUSOID = wp.constant(1)
HEIGHT_GRID = wp.constant(2)


@wp.struct
class TerrainData:
    """Free-surface height field and material-along-x table (see ``terrain.TerrainCfg``)."""

    kind: int
    z0: float
    amplitude: wp.vec2
    wavelength: wp.vec2
    grid: wp.array2d[float]
    grid_origin: wp.vec2
    grid_spacing: float
    num_materials: int
    material_table: wp.array2d[float]
    material_edges: wp.array[float]
    material_blend: float


@wp.func
def terrain_height(terrain: TerrainData, x: float, y: float) -> float:
    """Return the free-surface height z_s(x, y) [m]: flat, sinusoid, or bilinear grid clamped at its edges."""
    z = terrain.z0
    if terrain.kind == HEIGHT_SINUSOID:
        z += terrain.amplitude[0] * wp.sin(2.0 * wp.pi * x / terrain.wavelength[0])
        z += terrain.amplitude[1] * wp.sin(2.0 * wp.pi * y / terrain.wavelength[1])
    elif terrain.kind == HEIGHT_GRID:
        ny = terrain.grid.shape[0]
        nx = terrain.grid.shape[1]
        gx = wp.clamp((x - terrain.grid_origin[0]) / terrain.grid_spacing, 0.0, float(nx - 1))
        gy = wp.clamp((y - terrain.grid_origin[1]) / terrain.grid_spacing, 0.0, float(ny - 1))
        ix0 = wp.min(int(wp.floor(gx)), wp.max(nx - 2, 0))
        iy0 = wp.min(int(wp.floor(gy)), wp.max(ny - 2, 0))
        ix1 = wp.min(ix0 + 1, nx - 1)
        iy1 = wp.min(iy0 + 1, ny - 1)
        tx = gx - float(ix0)
        ty = gy - float(iy0)
        z_lo = terrain.grid[iy0, ix0] * (1.0 - tx) + terrain.grid[iy0, ix1] * tx
        z_hi = terrain.grid[iy1, ix0] * (1.0 - tx) + terrain.grid[iy1, ix1] * tx
        z += z_lo * (1.0 - ty) + z_hi * ty
    return z


@wp.func
def point_material(
    terrain: TerrainData,
    rho_c: wp.array[float],
    mu_int: wp.array[float],
    mu_surf: wp.array[float],
    worldid: int,
    x: float,
) -> wp.vec3:
    """Return (rho_c, mu_int, mu_surf) at world x: the terrain's blended table if set, else the world's."""
    if terrain.num_materials == 0:
        return wp.vec3(
            rho_c[worldid % rho_c.shape[0]], mu_int[worldid % mu_int.shape[0]], mu_surf[worldid % mu_surf.shape[0]]
        )
    t = terrain.material_table
    out = wp.vec3(t[0, 0], t[0, 1], t[0, 2])
    for j in range(terrain.num_materials - 1):
        s = 0.0
        if terrain.material_blend > 0.0:
            s = wp.clamp((x - terrain.material_edges[j]) / terrain.material_blend + 0.5, 0.0, 1.0)
        elif x >= terrain.material_edges[j]:
            s = 1.0
        out += s * wp.vec3(t[j + 1, 0] - t[j, 0], t[j + 1, 1] - t[j, 1], t[j + 1, 2] - t[j, 2])
    return out


@wp.func
def media_scaling(rho_c: float, mu_int: float, gravity: float) -> float:
    """Return xi_n = rho_c g (894 mu^3 - 386 mu^2 + 89 mu) [N/m^3] (Agarwal et al. PNAS 2023)."""
    return rho_c * gravity * (mu_int * (89.0 + mu_int * (-386.0 + 894.0 * mu_int)))


@wp.func
def foot_point_kinematics(
    pos: wp.vec3, rot: wp.mat33, lin_vel: wp.vec3, ang_vel: wp.vec3, point_b: wp.vec3, normal_b: wp.vec3
) -> wp.mat33:
    """Return rows (p_w, n_w, v_w): world position, outward normal, and velocity v + w x (R p_b) of a point."""
    r = rot * point_b
    return wp.matrix_from_rows(pos + r, rot * normal_b, lin_vel + wp.cross(ang_vel, r))


@wp.func
def element_kinematics(  # noqa: ANN201 (returns the tuple wp.mat33, float; Warp infers it)
    terrain: TerrainData,
    pos: wp.vec3,
    rot: wp.mat33,
    lin_vel: wp.vec3,
    ang_vel: wp.vec3,
    point_b: wp.vec3,
    normal_b: wp.vec3,
):
    """Return a foot element's kinematics rows (x, n, v) and its depth below the local free surface [m].

    The opening block of every element kernel (cone, 2D-RFT, 3D-RFT): :func:`foot_point_kinematics`, then
    depth = z_s(x, y) - z (positive below the surface, :func:`terrain_height`).
    """
    kin = foot_point_kinematics(pos, rot, lin_vel, ang_vel, point_b, normal_b)
    x = kin[0]
    return kin, terrain_height(terrain, x[0], x[1]) - x[2]


@wp.func
def write_element(
    force: wp.vec3,
    depth: float,
    vel: wp.vec3,
    point_force_out: wp.array3d[wp.vec3],
    point_depth_out: wp.array3d[float],
    point_vel_out: wp.array3d[wp.vec3],
    w: int,
    f: int,
    p: int,
) -> None:
    """Store one element's force [N], depth [m] and velocity [m/s] (the per-point outputs of compute())."""
    point_force_out[w, f, p] = force
    point_depth_out[w, f, p] = depth
    point_vel_out[w, f, p] = vel


@wp.func
def foot_partial_wrench(
    points_b: wp.array[wp.vec3],
    point_force: wp.array3d[wp.vec3],
    w: int,
    f: int,
    pos: wp.vec3,
    rot: wp.mat33,
    com: wp.vec3,
    start: int,
    stride: int,
) -> wp.spatial_vector:
    """Return (sum F_i, sum (p_i - p_com) x F_i) over points start, start + stride, ... in that order."""
    force = wp.vec3(0.0)
    torque = wp.vec3(0.0)
    for p in range(start, points_b.shape[0], stride):
        force_p = point_force[w, f, p]
        force += force_p
        # tau_com = sum (p_i - p_com) x F_i = tau_ankle + (p_ankle - p_com) x F
        torque += wp.cross(pos + rot * points_b[p] - com, force_p)
    return wp.spatial_vector(force, torque)


@wp.kernel
def foot_wrench_kernel(
    # Model:
    points_b: wp.array[wp.vec3],
    # Data in:
    foot_pos_in: wp.array2d[wp.vec3],
    foot_mat_in: wp.array2d[wp.mat33],
    foot_com_in: wp.array2d[wp.vec3],
    point_force_in: wp.array3d[wp.vec3],
    # Data out:
    wrench_out: wp.array2d[wp.spatial_vector],
    nan_count_out: wp.array[int],
) -> None:
    """Sum element forces and their moments about the foot's centre of mass (fixed order: deterministic)."""
    worldid, footid = wp.tid()
    pos = foot_pos_in[worldid, footid]
    rot = foot_mat_in[worldid, footid]
    com = foot_com_in[worldid, footid]
    if not (wp.isfinite(pos) and wp.isfinite(rot) and wp.isfinite(com)):
        if wp.isfinite(pos) and wp.isfinite(rot):
            wp.atomic_add(nan_count_out, 0, 1)  # non-finite CoM only (pose/velocity are counted per element)
        wrench_out[worldid, footid] = wp.spatial_vector(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        return
    wrench_out[worldid, footid] = foot_partial_wrench(points_b, point_force_in, worldid, footid, pos, rot, com, 0, 1)


def eval_foot_wrench(model: Any, inputs: tuple, wrench_out: wp.array) -> None:
    """Launch :func:`foot_wrench_kernel` over [num_worlds, num_feet]."""
    foot_pos, foot_mat, _, _, foot_com = inputs
    wp.launch(
        foot_wrench_kernel,
        dim=(model.num_worlds, model.num_feet),
        inputs=[model.points_b, foot_pos, foot_mat, foot_com, model.point_force],
        outputs=[wrench_out, model.nan_count],
        device=model.device,
    )


def tile_block_dim(num_points: int) -> int:
    """Threads per foot block of the tiled kernels: P rounded up to whole warps, at most 256 (CPU: resolves to 1)."""
    return min(256, 32 * ((num_points + 31) // 32))


@wp.func
def foot_inputs_finite(pos: wp.vec3, rot: wp.mat33, lin_vel: wp.vec3, ang_vel: wp.vec3) -> bool:
    """Return whether a foot's pose and velocities are all finite (else its elements get zero force)."""
    return wp.isfinite(pos) and wp.isfinite(rot) and wp.isfinite(lin_vel) and wp.isfinite(ang_vel)


@wp.func
def foot_wrench_block_sum(
    partial: wp.spatial_vector, pos: wp.vec3, rot: wp.mat33, com: wp.vec3, lane: int, nan_count_out: wp.array[int]
) -> wp.spatial_vector:
    """Sum the lanes' partial (force, torque about the CoM) over the block; zero for a non-finite foot pose.

    Every lane must call this (tile collective). The lanes' partials are summed by ``wp.tile_sum`` in a fixed
    tree order (deterministic; on CPU the block is one lane, so the order is the plain p = 0..P-1 loop of
    :func:`foot_wrench_kernel`). A non-finite CoM alone counts once in ``nan_count_out`` (pose and velocity
    are counted per element).
    """
    total = wp.tile_extract(wp.tile_sum(wp.tile(partial, preserve_type=True)), 0)
    if not (wp.isfinite(pos) and wp.isfinite(rot) and wp.isfinite(com)):
        if lane == 0 and wp.isfinite(pos) and wp.isfinite(rot):
            wp.atomic_add(nan_count_out, 0, 1)
        return wp.spatial_vector(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    return total


@wp.kernel
def foot_wrench_tiled_kernel(
    # Model:
    points_b: wp.array[wp.vec3],
    # Data in:
    foot_pos_in: wp.array2d[wp.vec3],
    foot_mat_in: wp.array2d[wp.mat33],
    foot_com_in: wp.array2d[wp.vec3],
    point_force_in: wp.array3d[wp.vec3],
    # Data out:
    wrench_out: wp.array2d[wp.spatial_vector],
    nan_count_out: wp.array[int],
) -> None:
    """Per-foot sum as :func:`foot_wrench_kernel`, one block per foot: lanes stride over the points, then a tile sum."""
    worldid, footid, lane = wp.tid()
    pos = foot_pos_in[worldid, footid]
    rot = foot_mat_in[worldid, footid]
    com = foot_com_in[worldid, footid]
    partial = foot_partial_wrench(points_b, point_force_in, worldid, footid, pos, rot, com, lane, wp.block_dim())
    wrench = foot_wrench_block_sum(partial, pos, rot, com, lane, nan_count_out)
    if lane == 0:
        wrench_out[worldid, footid] = wrench


def eval_foot_wrench_tiled(model: Any, inputs: tuple, wrench_out: wp.array) -> None:
    """Launch :func:`foot_wrench_tiled_kernel` over [num_worlds, num_feet] blocks of :func:`tile_block_dim` lanes."""
    foot_pos, foot_mat, _, _, foot_com = inputs
    wp.launch_tiled(
        foot_wrench_tiled_kernel,
        dim=(model.num_worlds, model.num_feet),
        inputs=[model.points_b, foot_pos, foot_mat, foot_com, model.point_force],
        outputs=[wrench_out, model.nan_count],
        block_dim=tile_block_dim(model.num_points),
        device=model.device,
    )


@wp.kernel
def scatter_values_kernel(
    # Data in:
    ids_in: wp.array[int],
    values_in: wp.array[float],
    # Data out:
    values_out: wp.array[float],
) -> None:
    """Write values_out[ids[i]] = values[i]."""
    i = wp.tid()
    values_out[ids_in[i]] = values_in[i]


def eval_scatter_values(ids: wp.array, values: wp.array, values_out: wp.array) -> None:
    """Launch :func:`scatter_values_kernel` (in-place update of a per-world parameter array)."""
    wp.launch(
        scatter_values_kernel, dim=ids.shape[0], inputs=[ids, values], outputs=[values_out], device=values_out.device
    )


@wp.kernel
def material_eta_kernel(
    # Model:
    rho_c: wp.array[float],
    mu_int: wp.array[float],
    gravity: float,
    xi_max: float,
    log_xi_min: float,
    log_xi_max: float,
    # Data in:
    ids_in: wp.array[int],
    # Data out:
    eta_out: wp.array[float],
    eta_log_out: wp.array[float],
) -> None:
    """Write eta = xi / xi_max and eta_log = (ln xi - ln xi_min) / (ln xi_max - ln xi_min) of world ids[i].

    xi = xi_n(rho_c, mu_int) of the world's current material (gmloco.contact.materials.eta, both scales).
    """
    i = wp.tid()
    w = ids_in[i]
    xi = media_scaling(rho_c[w], mu_int[w], gravity)
    eta_out[w] = xi / xi_max
    eta_log_out[w] = (wp.log(xi) - log_xi_min) / (log_xi_max - log_xi_min)


def eval_material_eta(model: Any, ids: wp.array, eta_out: wp.array, eta_log_out: wp.array) -> None:
    """Launch :func:`material_eta_kernel` over the worlds ``ids`` (after their rho_c / mu_int were written)."""
    dr = DR_RANGES_PAPER  # the range that defines eta (gmloco.contact.materials.eta)
    lo, hi = float(xi_n(dr.rho_c[0], dr.mu_int[0])), xi_max(dr)
    wp.launch(
        material_eta_kernel,
        dim=ids.shape[0],
        inputs=[model.rho_c, model.mu_int, GRAVITY, hi, math.log(lo), math.log(hi), ids],
        outputs=[eta_out, eta_log_out],
        device=model.device,
    )
