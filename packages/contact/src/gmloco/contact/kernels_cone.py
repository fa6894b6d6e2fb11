# SPDX-License-Identifier: Apache-2.0
"""Jammed-granular-cone RFT (Choi et al., Sci. Robotics 2023), GM-Loco closed form, single and multi point."""

from __future__ import annotations

from typing import Any

import warp as wp

from gmloco.contact.kernels_foot import read_foot_state, skip_element
from gmloco.contact.kernels_geometry import (
    TerrainData,
    element_kinematics,
    write_element,
)
from gmloco.contact.kernels_rft2d import coulomb_tangential
from gmloco.contact.kernels_state import (
    AT_REST_UNLOADING,
    AtRestParams,
    ElementState,
    at_rest_filter,
    elastic_depth,
    point_kernel_data,
)

__all__ = ["cone_flat_area", "cone_quasi_static", "eval_cone_point_forces"]


@wp.func
def cone_flat_area(z: float, r_h: float, k: float) -> float:
    """Return A_flat(z) = pi (r_h - k z)^2, 0 beyond z_c = r_h / k [m^2]."""
    r = wp.max(r_h - k * z, 0.0)
    return wp.pi * r * r


@wp.func
def cone_flat_integral(z: float, r_h: float, k: float) -> float:
    """Return I_flat(z) = int_0^z A_flat = (pi / 3k)(r_h^3 - (r_h - k z_clip)^3) [m^3]."""
    r = r_h - k * wp.clamp(z, 0.0, r_h / k)
    return wp.pi / (3.0 * k) * (r_h * r_h * r_h - r * r * r)


@wp.func
def cone_quasi_static(z: float, r_h: float, k: float, cos_theta: float, sigma_flat: float, sigma_cone: float) -> float:
    """Return F_qs = sigma_flat I_flat + sigma_cone (pi r_h^2 z - I_flat) / cos(theta) [N]."""
    i_flat = cone_flat_integral(z, r_h, k)
    return sigma_flat * i_flat + sigma_cone * (wp.pi * r_h * r_h * wp.max(z, 0.0) - i_flat) / cos_theta


@wp.kernel
def cone_point_force_kernel(
    # Model:
    points_b: wp.array[wp.vec3],
    radii: wp.array[float],
    sigma_flat: wp.array[float],
    sigma_cone: wp.array[float],
    mu_surf: wp.array[float],
    terrain: TerrainData,
    k_cone: float,
    cos_theta: float,
    mass_rate: float,
    c_d: float,
    eps_f: float,
    k_f: float,
    added_mass: int,
    dt: float,
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
    """Compute one cone point's force: quasi-static + drag while penetrating, plastic/elastic unloading."""
    w, f, p = wp.tid()
    pos, rot, lin_vel, ang_vel, finite = read_foot_state(
        foot_pos_in, foot_mat_in, foot_lin_vel_in, foot_ang_vel_in, w, f
    )
    if not finite:
        skip_element(point_force_out, point_depth_out, point_vel_out, nan_count_out, w, f, p)
        return
    kin, z = element_kinematics(terrain, pos, rot, lin_vel, ang_vel, points_b[p], wp.vec3(0.0, 0.0, -1.0))
    v = kin[2]
    z_dot = -v[2]
    z_max = state_in.depth_max[w, f, p]
    r_h = radii[p]
    s_flat = sigma_flat[w % sigma_flat.shape[0]]
    s_cone = sigma_cone[w % sigma_cone.shape[0]]
    f_n = 0.0
    if z > 0.0:
        if z_dot > 0.0 or z >= z_max - eps_f:  # GM-Loco rule: penetrating or at the deepest point
            f_n = cone_quasi_static(z, r_h, k_cone, cos_theta, s_flat, s_cone)
            if z_dot > 0.0:  # drag c_d M A_flat z_dot^2 (GM-Loco form of c_d m_a_dot z_dot)
                f_n += c_d * mass_rate * cone_flat_area(z, r_h, k_cone) * z_dot * z_dot
            if added_mass != 0:
                z_ddot = (z_dot + state_in.vel_prev[w, f, p][2]) / dt
                f_n += mass_rate * cone_flat_integral(z, r_h, k_cone) * z_ddot
            f_n = wp.max(f_n, 0.0)
        elif rest.mode == AT_REST_UNLOADING:
            d_eff = elastic_depth(z, z_max, z_dot, rest, state_in.ema_tau[w, f, p])
            f_n = cone_quasi_static(z_max, r_h, k_cone, cos_theta, s_flat, s_cone) * d_eff / z_max
    force = coulomb_tangential(f_n, v, mu_surf[w % mu_surf.shape[0]], k_f) + wp.vec3(0.0, 0.0, f_n)
    force = at_rest_filter(force, v, z, rest, state_in, w, f, p, 1)
    write_element(force, z, v, point_force_out, point_depth_out, point_vel_out, w, f, p)


def eval_cone_point_forces(model: Any, inputs: tuple, nan_count_out: wp.array) -> None:
    """Launch :func:`cone_point_force_kernel` over [num_worlds, num_feet, num_points]."""
    cfg = model.cfg
    wp.launch(
        cone_point_force_kernel,
        dim=model.point_depth.shape,
        inputs=[
            model.points_b,
            model.radii,
            model.sigma_flat,
            model.sigma_cone,
            model.mu_surf,
            model.terrain,
            model.k_cone,
            model.cos_theta,
            model.mass_rate,
            cfg.c_d,
            cfg.eps_f,
            cfg.k_f,
            int(cfg.enable_added_mass),
            cfg.dt,
            model.rest,
            *point_kernel_data(model, inputs),
        ],
        outputs=[model.point_force, model.point_depth, model.point_vel, nan_count_out],
        device=model.device,
    )
