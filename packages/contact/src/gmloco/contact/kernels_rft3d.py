# SPDX-License-Identifier: Apache-2.0
"""3D-RFT element forces (Agarwal, Goldman & Kamrin, PNAS 120 e2214017120, 2023), frame-free form."""

from __future__ import annotations

from typing import Any

import warp as wp

from gmloco.contact.kernels_geometry import (
    TerrainData,
    foot_inputs_finite,
    foot_point_kinematics,
    foot_wrench_block_sum,
    media_scaling,
    point_material,
    terrain_height,
    tile_block_dim,
)
from gmloco.contact.kernels_state import (
    AT_REST_EMA,
    AT_REST_NONE,
    AT_REST_UNLOADING,
    ema_filter,
    ema_rigidity,
    impact_damping,
    unloading_depth,
)

__all__ = [
    "RFT3DCoeffs",
    "eval_rft3d_foot_wrench",
    "eval_rft3d_point_forces",
    "rft3d_alpha",
    "rft3d_generic",
    "unit_velocity",
]

G_HAT = wp.constant(wp.vec3(0.0, 0.0, -1.0))

RFT3DCoeffs = wp.types.matrix(shape=(20, 3), dtype=wp.float32)
"""The 20 x 3 PNAS coefficients passed by value (kernel parameter: constant-bank operands, no loads)."""
CubicBasis = wp.types.vector(length=20, dtype=wp.float32)
"""The 20 PNAS SI monomials T_k(x1, x2, x3), in SI order."""


@wp.func
def unit_velocity(v: wp.vec3, v_eps: float) -> wp.vec3:
    """Return v / |v|, or g_hat when |v| < v_eps (spec 1.5: a foot at rest resists as if pressed down)."""
    speed = wp.length(v)
    if speed < v_eps:
        return G_HAT
    return v / speed


@wp.func
def cubic_fit(c: wp.array2d[float], j: int, x1: float, x2: float, x3: float) -> float:
    """Return f_j = sum_k c[k, j] T_k(x1, x2, x3) over the 20 PNAS SI monomials, in SI order."""
    f = c[0, j] + c[1, j] * x1 + c[2, j] * x2 + c[3, j] * x3
    f += c[4, j] * x1 * x1 + c[5, j] * x2 * x2 + c[6, j] * x3 * x3
    f += c[7, j] * x1 * x2 + c[8, j] * x2 * x3 + c[9, j] * x3 * x1
    f += c[10, j] * x1 * x1 * x1 + c[11, j] * x2 * x2 * x2 + c[12, j] * x3 * x3 * x3
    f += c[13, j] * x1 * x2 * x2 + c[14, j] * x2 * x1 * x1 + c[15, j] * x2 * x3 * x3
    f += c[16, j] * x3 * x2 * x2 + c[17, j] * x3 * x1 * x1 + c[18, j] * x1 * x3 * x3
    f += c[19, j] * x1 * x2 * x3
    return f


@wp.func
def cubic_basis(x1: float, x2: float, x3: float) -> CubicBasis:
    """Return the 20 PNAS SI monomials once, so the three fits cost 3 x 20 FMAs (not 3 x ~64 flops)."""
    x11 = x1 * x1
    x22 = x2 * x2
    x33 = x3 * x3
    return CubicBasis(
        1.0,
        x1,
        x2,
        x3,
        x11,
        x22,
        x33,
        x1 * x2,
        x2 * x3,
        x3 * x1,
        x11 * x1,
        x22 * x2,
        x33 * x3,
        x1 * x22,
        x2 * x11,
        x2 * x33,
        x3 * x22,
        x3 * x11,
        x1 * x33,
        x1 * x2 * x3,
    )


@wp.func
def rft3d_generic(n: wp.vec3, v_hat: wp.vec3, coeffs: wp.array2d[float]) -> wp.vec3:
    """Return G = f1 n_e + f2 v_hat + f3 g_hat with n_e = n if n_z < 0 else -n (PNAS 2023, spec 1.1)."""
    n_e = n
    if n[2] >= 0.0:
        n_e = -n
    x1 = wp.dot(G_HAT, v_hat)
    x2 = wp.dot(G_HAT, n_e)
    x3 = wp.dot(n_e, v_hat)
    f1 = cubic_fit(coeffs, 0, x1, x2, x3)
    f2 = cubic_fit(coeffs, 1, x1, x2, x3)
    f3 = cubic_fit(coeffs, 2, x1, x2, x3)
    return f1 * n_e + f2 * v_hat + f3 * G_HAT


@wp.func
def rft3d_generic(n: wp.vec3, v_hat: wp.vec3, coeffs: RFT3DCoeffs) -> wp.vec3:  # noqa: F811
    """Overload of :func:`rft3d_generic` for by-value coefficients: basis once, f = T^T C (same G, float32 round-off)."""
    n_e = n
    if n[2] >= 0.0:
        n_e = -n
    x1 = wp.dot(G_HAT, v_hat)
    x2 = wp.dot(G_HAT, n_e)
    x3 = wp.dot(n_e, v_hat)
    f = wp.mul(cubic_basis(x1, x2, x3), coeffs)
    return f[0] * n_e + f[1] * v_hat + f[2] * G_HAT


@wp.func
def rft3d_alpha(g: wp.vec3, n: wp.vec3, xi: float, mu_surf: float, v_hat: wp.vec3, sign_fix: int) -> wp.vec3:
    """Return alpha = xi [G_n + min(1, mu |G_n| / (|G_t| + 1e-6)) G_t] [N/m^3] (PNAS surface-friction cone)."""
    g_dot_n = wp.dot(g, n)
    g_n = g_dot_n * n
    g_t = g - g_n
    if sign_fix != 0:  # reference MATLAB findAlpha.m corrections (spec 1.1.7)
        g_n = -wp.abs(g_dot_n) * n
        if wp.dot(g_t, v_hat) > 0.0:
            g_t = -g_t
    scale = wp.min(1.0, mu_surf * wp.length(g_n) / (wp.length(g_t) + 1.0e-6))
    return xi * (g_n + scale * g_t)


@wp.func
def rft3d_plastic_force(
    n: wp.vec3,
    v: wp.vec3,
    depth: float,
    area: float,
    xi: float,
    mu_surf: float,
    coeffs: Any,
    v_eps: float,
    sign_fix: int,
) -> wp.vec3:
    """Return F = alpha depth dS for a submerged leading element (n.v_hat >= 0), else 0 [N].

    ``coeffs``: wp.array2d[float] (reference path) or :data:`RFT3DCoeffs` (fused path).
    """
    v_hat = unit_velocity(v, v_eps)
    if depth <= 0.0 or wp.dot(n, v_hat) < 0.0:
        return wp.vec3(0.0)
    return rft3d_alpha(rft3d_generic(n, v_hat, coeffs), n, xi, mu_surf, v_hat, sign_fix) * (depth * area)


@wp.func
def rft3d_elastic_force(
    n: wp.vec3,
    v: wp.vec3,
    depth: float,
    depth_max: float,
    area: float,
    xi: float,
    mu_surf: float,
    coeffs: Any,
    ratio: float,
    damping: float,
    speed: float,
    tau_rev: float,
    tangential_damping: float,
) -> wp.vec3:
    """Return the elastic-branch force inside the crater: static alpha on d_eff plus capped viscous friction [N].

    d_eff is the unloading line with Kelvin-Voigt and impact damping (:func:`impact_damping`).

    F_t = -min(mu |F.n|, c_t dS |v_t|) v_t / |v_t| in the element plane (the viscous cap keeps the explicit
    coupling stable, like GM-Loco's k_f for its baselines).
    """
    alpha_s = rft3d_alpha(rft3d_generic(n, G_HAT, coeffs), n, xi, mu_surf, G_HAT, 0)
    d_eff = impact_damping(unloading_depth(depth, depth_max, ratio, damping, -v[2]), depth_max, -v[2], speed, tau_rev)
    f = alpha_s * (d_eff * area)
    v_t = v - wp.dot(v, n) * n
    speed = wp.length(v_t)
    if speed <= 0.0:
        return f
    return f - (wp.min(mu_surf * wp.abs(wp.dot(f, n)), tangential_damping * area * speed) / speed) * v_t


@wp.kernel
def rft3d_point_force_kernel(
    # Model:
    coeffs: wp.array2d[float],
    points_b: wp.array[wp.vec3],
    normals_b: wp.array[wp.vec3],
    areas: wp.array[float],
    rho_c: wp.array[float],
    mu_int: wp.array[float],
    mu_surf: wp.array[float],
    terrain: TerrainData,
    gravity: float,
    v_eps: float,
    sign_fix: int,
    at_rest: int,
    unloading_ratio: float,
    unloading_damping: float,
    unloading_speed: float,
    tangential_damping: float,
    ema_rate: float,
    # Data in:
    foot_pos_in: wp.array2d[wp.vec3],
    foot_mat_in: wp.array2d[wp.mat33],
    foot_lin_vel_in: wp.array2d[wp.vec3],
    foot_ang_vel_in: wp.array2d[wp.vec3],
    depth_max_in: wp.array3d[float],
    ema_tau_in: wp.array3d[float],
    force_prev_in: wp.array3d[wp.vec3],
    vel_prev_in: wp.array3d[wp.vec3],
    # Data out:
    point_force_out: wp.array3d[wp.vec3],
    point_depth_out: wp.array3d[float],
    point_vel_out: wp.array3d[wp.vec3],
    nan_count_out: wp.array[int],
) -> None:
    """Compute one element's 3D-RFT force, depth and velocity for [world, foot, point]."""
    w, f, p = wp.tid()
    pos = foot_pos_in[w, f]
    rot = foot_mat_in[w, f]
    lin_vel = foot_lin_vel_in[w, f]
    ang_vel = foot_ang_vel_in[w, f]
    if not (wp.isfinite(pos) and wp.isfinite(rot) and wp.isfinite(lin_vel) and wp.isfinite(ang_vel)):
        wp.atomic_add(nan_count_out, 0, 1)
        point_force_out[w, f, p] = wp.vec3(0.0)
        point_depth_out[w, f, p] = 0.0
        point_vel_out[w, f, p] = wp.vec3(0.0)
        return
    kin = foot_point_kinematics(pos, rot, lin_vel, ang_vel, points_b[p], normals_b[p])
    x = kin[0]
    n = kin[1]
    v = kin[2]
    depth = terrain_height(terrain, x[0], x[1]) - x[2]
    mat = point_material(terrain, rho_c, mu_int, mu_surf, w, x[0])
    xi = media_scaling(mat[0], mat[1], gravity)
    depth_max = depth_max_in[w, f, p]
    force = wp.vec3(0.0)
    if at_rest == AT_REST_UNLOADING and depth > 0.0 and depth < depth_max:
        force = rft3d_elastic_force(
            n,
            v,
            depth,
            depth_max,
            areas[p],
            xi,
            mat[2],
            coeffs,
            unloading_ratio,
            unloading_damping,
            unloading_speed,
            ema_tau_in[w, f, p],
            tangential_damping,
        )
    else:
        force = rft3d_plastic_force(n, v, depth, areas[p], xi, mat[2], coeffs, v_eps, sign_fix)
    if at_rest == AT_REST_EMA:
        tau = ema_rigidity(ema_tau_in[w, f, p], v, vel_prev_in[w, f, p], depth, ema_rate, 0)
        force = ema_filter(force, force_prev_in[w, f, p], tau)
    point_force_out[w, f, p] = force
    point_depth_out[w, f, p] = depth
    point_vel_out[w, f, p] = v


def eval_rft3d_point_forces(model: Any, inputs: tuple, nan_count_out: wp.array) -> None:
    """Launch :func:`rft3d_point_force_kernel` over [num_worlds, num_feet, num_points]."""
    cfg = model.cfg
    foot_pos, foot_mat, foot_lin_vel, foot_ang_vel, _ = inputs
    wp.launch(
        rft3d_point_force_kernel,
        dim=model.point_depth.shape,
        inputs=[
            model.coeffs,
            model.points_b,
            model.normals_b,
            model.areas,
            model.rho_c,
            model.mu_int,
            model.mu_surf,
            model.terrain,
            cfg.gravity,
            cfg.v_eps,
            int(cfg.sign_fix),
            model.at_rest_code,
            cfg.unloading_ratio,
            cfg.unloading_damping,
            cfg.unloading_speed,
            cfg.tangential_damping,
            cfg.ema_rate,
            foot_pos,
            foot_mat,
            foot_lin_vel,
            foot_ang_vel,
            model.depth_max,
            model.ema_tau,
            model.force_prev,
            model.vel_prev,
        ],
        outputs=[model.point_force, model.point_depth, model.point_vel, nan_count_out],
        device=model.device,
    )


@wp.func
def rft3d_element_force(
    n: wp.vec3,
    v: wp.vec3,
    depth: float,
    area: float,
    xi: float,
    mu_surf: float,
    coeffs: RFT3DCoeffs,
    v_eps: float,
    sign_fix: int,
    at_rest: int,
    unloading_ratio: float,
    unloading_damping: float,
    unloading_speed: float,
    tangential_damping: float,
    ema_rate: float,
    depth_max: float,
    ema_tau: float,
    force_prev: wp.vec3,
    vel_prev: wp.vec3,
) -> wp.vec3:
    """Return one element's force exactly as :func:`rft3d_point_force_kernel` does (elastic / plastic / EMA) [N]."""
    force = wp.vec3(0.0)
    if at_rest == AT_REST_UNLOADING and depth > 0.0 and depth < depth_max:
        force = rft3d_elastic_force(
            n,
            v,
            depth,
            depth_max,
            area,
            xi,
            mu_surf,
            coeffs,
            unloading_ratio,
            unloading_damping,
            unloading_speed,
            ema_tau,
            tangential_damping,
        )
    else:
        force = rft3d_plastic_force(n, v, depth, area, xi, mu_surf, coeffs, v_eps, sign_fix)
    if at_rest == AT_REST_EMA:
        force = ema_filter(force, force_prev, ema_rigidity(ema_tau, v, vel_prev, depth, ema_rate, 0))
    return force


@wp.kernel
def rft3d_foot_wrench_kernel(
    # Model:
    coeffs: RFT3DCoeffs,
    points_b: wp.array[wp.vec3],
    normals_b: wp.array[wp.vec3],
    areas: wp.array[float],
    rho_c: wp.array[float],
    mu_int: wp.array[float],
    mu_surf: wp.array[float],
    terrain: TerrainData,
    gravity: float,
    v_eps: float,
    sign_fix: int,
    at_rest: int,
    unloading_ratio: float,
    unloading_damping: float,
    unloading_speed: float,
    tangential_damping: float,
    ema_rate: float,
    # Data in:
    foot_pos_in: wp.array2d[wp.vec3],
    foot_mat_in: wp.array2d[wp.mat33],
    foot_lin_vel_in: wp.array2d[wp.vec3],
    foot_ang_vel_in: wp.array2d[wp.vec3],
    foot_com_in: wp.array2d[wp.vec3],
    depth_max_in: wp.array3d[float],
    ema_tau_in: wp.array3d[float],
    force_prev_in: wp.array3d[wp.vec3],
    vel_prev_in: wp.array3d[wp.vec3],
    # Data out:
    point_force_out: wp.array3d[wp.vec3],
    point_depth_out: wp.array3d[float],
    point_vel_out: wp.array3d[wp.vec3],
    wrench_out: wp.array2d[wp.spatial_vector],
    nan_count_out: wp.array[int],
) -> None:
    """3D-RFT element forces and their per-foot wrench in one pass: one block per foot, lanes stride over points.

    Same element outputs as :func:`rft3d_point_force_kernel` and the same wrench as :func:`foot_wrench_kernel`
    (float32 round-off: cubic in basis form, tile-sum order). Emerged elements (depth <= 0) skip the material,
    xi and RFT evaluation: their force is exactly zero in every at-rest mode (the EMA weight is 0 out of
    contact). State is read only (depth_max for submerged elements; the other fields in their branches).
    """
    w, f, lane = wp.tid()
    pos = foot_pos_in[w, f]
    rot = foot_mat_in[w, f]
    lin_vel = foot_lin_vel_in[w, f]
    ang_vel = foot_ang_vel_in[w, f]
    com = foot_com_in[w, f]
    finite = foot_inputs_finite(pos, rot, lin_vel, ang_vel)
    force_sum = wp.vec3(0.0)
    torque_sum = wp.vec3(0.0)
    for p in range(lane, points_b.shape[0], wp.block_dim()):
        force = wp.vec3(0.0)
        depth = 0.0
        v = wp.vec3(0.0)
        if finite:
            kin = foot_point_kinematics(pos, rot, lin_vel, ang_vel, points_b[p], normals_b[p])
            x = kin[0]
            v = kin[2]
            depth = terrain_height(terrain, x[0], x[1]) - x[2]
            if depth > 0.0 or at_rest == AT_REST_EMA:
                mat = point_material(terrain, rho_c, mu_int, mu_surf, w, x[0])
                ema_tau = 0.0
                force_prev = wp.vec3(0.0)
                vel_prev = wp.vec3(0.0)
                if at_rest != AT_REST_NONE:
                    ema_tau = ema_tau_in[w, f, p]
                if at_rest == AT_REST_EMA:
                    force_prev = force_prev_in[w, f, p]
                    vel_prev = vel_prev_in[w, f, p]
                force = rft3d_element_force(
                    kin[1],
                    v,
                    depth,
                    areas[p],
                    media_scaling(mat[0], mat[1], gravity),
                    mat[2],
                    coeffs,
                    v_eps,
                    sign_fix,
                    at_rest,
                    unloading_ratio,
                    unloading_damping,
                    unloading_speed,
                    tangential_damping,
                    ema_rate,
                    depth_max_in[w, f, p],
                    ema_tau,
                    force_prev,
                    vel_prev,
                )
                force_sum += force
                # tau_com = sum (p_i - p_com) x F_i, as foot_wrench_kernel (x = pos + R p_b)
                torque_sum += wp.cross(x - com, force)
        else:
            wp.atomic_add(nan_count_out, 0, 1)
        point_force_out[w, f, p] = force
        point_depth_out[w, f, p] = depth
        point_vel_out[w, f, p] = v
    wrench = foot_wrench_block_sum(wp.spatial_vector(force_sum, torque_sum), pos, rot, com, lane, nan_count_out)
    if lane == 0:
        wrench_out[w, f] = wrench


def eval_rft3d_foot_wrench(model: Any, inputs: tuple, wrench_out: wp.array) -> None:
    """Launch :func:`rft3d_foot_wrench_kernel` over [num_worlds, num_feet] blocks (fused compute())."""
    cfg = model.cfg
    foot_pos, foot_mat, foot_lin_vel, foot_ang_vel, foot_com = inputs
    wp.launch_tiled(
        rft3d_foot_wrench_kernel,
        dim=(model.num_worlds, model.num_feet),
        inputs=[
            model.coeffs_by_value,
            model.points_b,
            model.normals_b,
            model.areas,
            model.rho_c,
            model.mu_int,
            model.mu_surf,
            model.terrain,
            cfg.gravity,
            cfg.v_eps,
            int(cfg.sign_fix),
            model.at_rest_code,
            cfg.unloading_ratio,
            cfg.unloading_damping,
            cfg.unloading_speed,
            cfg.tangential_damping,
            cfg.ema_rate,
            foot_pos,
            foot_mat,
            foot_lin_vel,
            foot_ang_vel,
            foot_com,
            model.depth_max,
            model.ema_tau,
            model.force_prev,
            model.vel_prev,
        ],
        outputs=[model.point_force, model.point_depth, model.point_vel, wrench_out, model.nan_count],
        block_dim=tile_block_dim(model.num_points),
        device=model.device,
    )
