# SPDX-License-Identifier: Apache-2.0
"""Warp kernels shared by all models: foot kinematics, terrain queries, wrench reduction, material scatter."""

from __future__ import annotations

from typing import Any

import warp as wp

__all__ = [
    "TerrainData",
    "eval_foot_wrench",
    "eval_scatter_values",
    "foot_point_kinematics",
    "media_scaling",
    "point_material",
    "terrain_height",
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
    force = wp.vec3(0.0)
    torque = wp.vec3(0.0)
    for p in range(points_b.shape[0]):
        f = point_force_in[worldid, footid, p]
        force += f
        # tau_com = sum (p_i - p_com) x F_i = tau_ankle + (p_ankle - p_com) x F
        torque += wp.cross(pos + rot * points_b[p] - com, f)
    wrench_out[worldid, footid] = wp.spatial_vector(force, torque)


def eval_foot_wrench(model: Any, inputs: tuple, wrench_out: wp.array2d) -> None:
    """Launch :func:`foot_wrench_kernel` over [num_worlds, num_feet]."""
    foot_pos, foot_mat, _, _, foot_com = inputs
    wp.launch(
        foot_wrench_kernel,
        dim=(model.num_worlds, model.num_feet),
        inputs=[model.points_b, foot_pos, foot_mat, foot_com, model.point_force],
        outputs=[wrench_out, model.nan_count],
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
