# SPDX-License-Identifier: Apache-2.0
"""Heuristic-RFT element forces: Li, Zhang & Goldman (Science 2013) 2D-RFT normal force + Coulomb tangential."""

from __future__ import annotations

from typing import Any

import warp as wp

from gmloco.contact.kernels_foot import read_foot_state, skip_element
from gmloco.contact.kernels_geometry import (
    TerrainData,
    element_kinematics,
    media_scaling,
    point_material,
    write_element,
)
from gmloco.contact.kernels_rft3d import G_HAT, unit_velocity
from gmloco.contact.kernels_state import (
    AT_REST_UNLOADING,
    AtRestParams,
    ElementState,
    at_rest_filter,
    elastic_depth,
    point_kernel_data,
    rft_element_model,
)

__all__ = ["eval_heuristic_point_forces", "rft2d_alpha_z", "rft2d_angles"]


@wp.func
def rft2d_angles(n: wp.vec3, v_hat: wp.vec3) -> wp.vec2:
    """Return (beta, gamma) [rad]: e_r from horizontal v, else n, else +x; four-case beta (spec 1.2)."""
    e_r = wp.vec3(1.0, 0.0, 0.0)
    h_n = wp.vec3(n[0], n[1], 0.0)
    h_v = wp.vec3(v_hat[0], v_hat[1], 0.0)
    if wp.length(h_v) > 1.0e-12:
        e_r = wp.normalize(h_v)
    elif wp.length(h_n) > 1.0e-12:
        e_r = wp.normalize(h_n)
    gamma = wp.acos(wp.clamp(wp.dot(v_hat, e_r), -1.0, 1.0))
    if v_hat[2] > 0.0:
        gamma = -gamma
    a = wp.acos(wp.clamp(n[2], -1.0, 1.0))
    beta = 0.0
    if wp.dot(n, e_r) >= 0.0:
        beta = -a
        if n[2] < 0.0:
            beta = wp.pi - a
    else:
        beta = a
        if n[2] < 0.0:
            beta = -wp.pi + a
    return wp.vec2(beta, gamma)


@wp.func
def rft2d_alpha_z(c: wp.array[float], beta: float, gamma: float) -> float:
    """Return alpha_z = A00 + A10 cos 2b + B11 sin(2b+g) + B01 sin g + B-11 sin(-2b+g) (Li 2013, Table S2)."""
    return (
        c[0]
        + c[1] * wp.cos(2.0 * beta)
        + c[2] * wp.sin(2.0 * beta + gamma)
        + c[3] * wp.sin(gamma)
        + c[4] * wp.sin(-2.0 * beta + gamma)
    )


@wp.func
def coulomb_tangential(f_z: float, v: wp.vec3, mu_surf: float, k_f: float) -> wp.vec3:
    """Return -min(mu F_z, k_f |v_t|) v_t / |v_t| in the horizontal plane [N] (F_z clamped >= 0 first)."""
    v_t = wp.vec3(v[0], v[1], 0.0)
    speed = wp.length(v_t)
    if speed <= 0.0:
        return wp.vec3(0.0)
    return -wp.min(mu_surf * f_z, k_f * speed) * v_t / speed


@wp.kernel
def heuristic_point_force_kernel(
    # Model:
    coeffs: wp.array[float],
    dimensional: int,
    points_b: wp.array[wp.vec3],
    normals_b: wp.array[wp.vec3],
    areas: wp.array[float],
    rho_c: wp.array[float],
    mu_int: wp.array[float],
    mu_surf: wp.array[float],
    terrain: TerrainData,
    gravity: float,
    v_eps: float,
    k_f: float,
    rest: AtRestParams,
    # Data in:
    foot_pos_in: wp.array2d[wp.vec3],
    foot_mat_in: wp.array2d[wp.mat33],
    foot_lin_vel_in: wp.array2d[wp.vec3],
    foot_ang_vel_in: wp.array2d[wp.vec3],
    state_in: ElementState,
    # Data out:
    point_force_out: wp.array3d[wp.vec3],
    point_depth_out: wp.array3d[float],
    point_vel_out: wp.array3d[wp.vec3],
    nan_count_out: wp.array[int],
) -> None:
    """Compute one element's Heuristic-RFT force (no leading-edge mask; F_z >= 0 before Coulomb)."""
    w, f, p = wp.tid()
    pos, rot, lin_vel, ang_vel, finite = read_foot_state(
        foot_pos_in, foot_mat_in, foot_lin_vel_in, foot_ang_vel_in, w, f
    )
    if not finite:
        skip_element(point_force_out, point_depth_out, point_vel_out, nan_count_out, w, f, p)
        return
    kin, depth = element_kinematics(terrain, pos, rot, lin_vel, ang_vel, points_b[p], normals_b[p])
    x = kin[0]
    n = kin[1]
    v = kin[2]
    mat = point_material(terrain, rho_c, mu_int, mu_surf, w, x[0])
    scale = 1.0e6  # N/cm^3 -> N/m^3 for the dimensional poppy-seed sets
    if dimensional == 0:
        scale = media_scaling(mat[0], mat[1], gravity)
    v_hat = unit_velocity(v, v_eps)
    depth_eff = depth
    depth_max = state_in.depth_max[w, f, p]
    if rest.mode == AT_REST_UNLOADING and depth > 0.0 and depth < depth_max:
        v_hat = G_HAT  # elastic branch: static resistance on the unloading line
        depth_eff = elastic_depth(depth, depth_max, -v[2], rest, state_in.ema_tau[w, f, p])
    force = wp.vec3(0.0)
    if depth > 0.0:
        angles = rft2d_angles(n, v_hat)
        f_z = wp.max(0.0, scale * rft2d_alpha_z(coeffs, angles[0], angles[1]) * depth_eff * areas[p])
        force = coulomb_tangential(f_z, v, mat[2], k_f) + wp.vec3(0.0, 0.0, f_z)
    force = at_rest_filter(force, v, depth, rest, state_in, w, f, p, 1)
    write_element(force, depth, v, point_force_out, point_depth_out, point_vel_out, w, f, p)


def eval_heuristic_point_forces(model: Any, inputs: tuple, nan_count_out: wp.array) -> None:
    """Launch :func:`heuristic_point_force_kernel` over [num_worlds, num_feet, num_points]."""
    cfg = model.cfg
    wp.launch(
        heuristic_point_force_kernel,
        dim=model.point_depth.shape,
        inputs=[
            model.coeffs,
            model.dimensional,
            *rft_element_model(model),
            cfg.k_f,
            model.rest,
            *point_kernel_data(model, inputs),
        ],
        outputs=[model.point_force, model.point_depth, model.point_vel, nan_count_out],
        device=model.device,
    )
