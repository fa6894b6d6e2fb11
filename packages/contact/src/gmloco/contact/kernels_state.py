# SPDX-License-Identifier: Apache-2.0
"""At-rest regularization, the structs every kernel shares, and the once-per-substep state update.

Elastic unloading, impact damping, crater friction with stick anchors and the EMA filter; ``AtRestParams`` and
``ElementState``; the state update and reset kernels.
"""

from __future__ import annotations

from typing import Any

import warp as wp

from gmloco.contact.kernels_foot import read_foot_state
from gmloco.contact.kernels_geometry import TerrainData, foot_point_kinematics, terrain_height

__all__ = [
    "AT_REST_CODES",
    "AtRestParams",
    "ElementState",
    "advance_element_state",
    "advance_stick_anchor",
    "advance_travel",
    "at_rest_filter",
    "crater_friction",
    "elastic_depth",
    "ema_filter",
    "ema_rigidity",
    "eval_reset_state",
    "eval_state_update",
    "eval_zero_wrench",
    "impact_damping",
    "point_kernel_data",
    "rft_element_model",
    "unloading_depth",
]

AT_REST_NONE = wp.constant(0)
AT_REST_UNLOADING = wp.constant(1)
AT_REST_EMA = wp.constant(2)
AT_REST_CODES: dict[str, int] = {"none": 0, "unloading": 1, "ema": 2}
"""Integer codes of the at-rest modes used by the kernels."""


@wp.struct
class AtRestParams:
    """At-rest parameters of a model (``config._AtRestCfg``), one by-value kernel argument for every model."""

    mode: int
    unloading_ratio: float
    unloading_damping: float
    unloading_speed: float
    tangential_damping: float
    ema_rate: float
    stick_distance: float
    footprint_radius: float
    loosening_dt: float
    erosion_rate: float
    erosion_restore: float


@wp.struct
class ElementState:
    """Per-element memory [W, F, P], written only by update_state() / reset(); read only by compute()."""

    depth_max: wp.array3d[float]
    ema_tau: wp.array3d[float]
    force_prev: wp.array3d[wp.vec3]
    vel_prev: wp.array3d[wp.vec3]
    anchor: wp.array3d[wp.vec3]
    footprint: wp.array3d[wp.vec3]
    travel: wp.array3d[float]


@wp.func
def unloading_depth(depth: float, depth_max: float, ratio: float, damping: float, depth_rate: float) -> float:
    """Return the elastic-branch effective depth max(0, z_max - r (z_max - d) + tau r d_dot) [m].

    A linear elastic unloading line of stiffness r times the secant loading stiffness: it equals z_max at
    d = z_max and vanishes once the element has risen by z_max / r (project choice, README "At rest").
    """
    return wp.max(0.0, depth_max - ratio * (depth_max - depth) + damping * ratio * depth_rate)


@wp.func
def impact_damping(depth_eff: float, depth_max: float, depth_rate: float, speed: float, tau_rev: float) -> float:
    """Return the elastic-branch depth after impact damping, clamp(d_eff (1 + d_dot / u0), 0, z_max) [m].

    Hunt-Crossley-like: the damping force is proportional to the elastic force, so a body recovering from an
    impact rises no faster than about u0 (1 - F_static / F_el) and arrives at rest at its static depth. It acts
    only while the reversal counter tau_r < 1 (at most one velocity reversal in contact), which cuts it off for
    step-rate (Nyquist) oscillations that an explicit damper would feed. The clamp at z_max keeps the elastic
    branch at or below the yield force of its crater (project choice, README "At rest"); u0 <= 0 disables the
    damping but keeps the clamp.
    """
    d = depth_eff
    if speed > 0.0 and tau_rev < 1.0:
        d = d * (1.0 + depth_rate / speed)
    return wp.clamp(d, 0.0, depth_max)


@wp.func
def elastic_depth(depth: float, depth_max: float, depth_rate: float, rest: AtRestParams, tau_rev: float) -> float:
    """Return the elastic-branch effective depth: :func:`unloading_depth`, then :func:`impact_damping` [m]."""
    d_el = unloading_depth(depth, depth_max, rest.unloading_ratio, rest.unloading_damping, depth_rate)
    return impact_damping(d_el, depth_max, depth_rate, rest.unloading_speed, tau_rev)


@wp.func
def ema_rigidity(
    tau_prev: float, vel: wp.vec3, vel_prev: wp.vec3, depth: float, rate: float, vertical_only: int
) -> float:
    """Return the EMA rigidity tau_r after this step (Choi 2023 S16 as used by GM-Loco).

    tau_r += c_r on a velocity reversal (v.v_prev < 0, or v_z v_z,prev < 0 for 2D/cone) while tau_r < 1;
    tau_r = 0 out of contact.
    """
    if depth <= 0.0:
        return 0.0
    reversal = wp.dot(vel, vel_prev) < 0.0
    if vertical_only != 0:
        reversal = vel[2] * vel_prev[2] < 0.0
    tau = tau_prev
    if reversal and tau < 1.0:
        tau = wp.min(1.0, tau + rate)
    return tau


@wp.func
def ema_filter(force: wp.vec3, force_prev: wp.vec3, tau: float) -> wp.vec3:
    """Return (1 - 0.8 tau) F + 0.8 tau F_prev."""
    return (1.0 - 0.8 * tau) * force + 0.8 * tau * force_prev


@wp.func
def at_rest_filter(
    force: wp.vec3,
    vel: wp.vec3,
    depth: float,
    rest: AtRestParams,
    state: ElementState,
    w: int,
    f: int,
    p: int,
    vertical_only: int,
) -> wp.vec3:
    """Return the element force after the EMA filter in ``"ema"`` mode, else ``force`` unchanged [N]."""
    if rest.mode != AT_REST_EMA:
        return force
    tau = ema_rigidity(state.ema_tau[w, f, p], vel, state.vel_prev[w, f, p], depth, rest.ema_rate, vertical_only)
    return ema_filter(force, state.force_prev[w, f, p], tau)


@wp.func
def crater_friction(
    force: wp.vec3, n: wp.vec3, v: wp.vec3, offset: wp.vec3, mu: float, damping: float, distance: float
) -> wp.vec3:
    """Return the tangential force of an element in its crater, F_t = T min(1, mu |F.n| / |T|) [N].

    T = -(mu |F.n| / s0) s_t - c v_t: a Cundall-Strack tangential spring on the offset s_t from the stick anchor
    (stiffness mu |F.n| / s0, so it reaches the Coulomb force at the mobilization distance s0 = ``distance``;
    s0 <= 0: no spring) plus the viscous term c v_t (``damping`` = c_t dS [N s/m]); s_t and v_t are the
    components in the element plane. With s0 <= 0 this is the viscous-capped Coulomb law
    -min(mu |F.n|, c |v_t|) v_t / |v_t| (README, "Static friction in the crater").
    """
    limit = mu * wp.abs(wp.dot(force, n))
    trial = -damping * tangential(v, n)
    if distance > 0.0:
        trial -= (limit / distance) * tangential(offset, n)
    mag = wp.length(trial)
    if mag <= limit:
        return trial
    return trial * (limit / mag)


@wp.func
def tangential(vec: wp.vec3, n: wp.vec3) -> wp.vec3:
    """Return the component of ``vec`` in the plane normal to the unit vector ``n``."""
    return vec - wp.dot(vec, n) * n


@wp.func
def advance_stick_anchor(
    anchor_out: wp.array3d[wp.vec3],
    w: int,
    f: int,
    p: int,
    x: wp.vec3,
    n: wp.vec3,
    depth: float,
    depth_max: float,
    distance: float,
) -> None:
    """Advance a submerged element's stick anchor (Cundall-Strack tangential spring with a Coulomb slider).

    At touch-down (z_max = 0 before this update) the anchor is the element's position x. In contact, the
    tangential offset s_t of x from the anchor is limited to ``distance``: beyond it the anchor slides after
    the element, so the spring mu |F_n| s_t / distance never exceeds the Coulomb force (README, "Static
    friction in the crater"). Unchanged anchors are not rewritten.
    """
    if depth >= depth_max:
        anchor_out[w, f, p] = x
        return
    s_t = tangential(x - anchor_out[w, f, p], n)
    length = wp.length(s_t)
    if length > distance:
        anchor_out[w, f, p] = x - s_t * (distance / length)


@wp.func
def footprint_near(footprint: wp.vec3, x: wp.vec3, radius: float) -> bool:
    """Return whether x lies horizontally within ``radius`` [m] of the footprint position."""
    dx = x[0] - footprint[0]
    dy = x[1] - footprint[1]
    return dx * dx + dy * dy < radius * radius


@wp.func
def advance_element_state(
    state: ElementState,
    rest: AtRestParams,
    vertical_only: int,
    w: int,
    f: int,
    p: int,
    x: wp.vec3,
    n: wp.vec3,
    vel: wp.vec3,
    depth: float,
    force: wp.vec3,
) -> None:
    """Advance element [w, f, p]'s memory past this substep: stick anchor, z_max, EMA rigidity, velocity, force.

    z_max is reset out of contact, unless footprint memory is on (``rest.footprint_radius`` > 0) and the element
    is still within that radius of where it last reached z_max (``state.footprint``, written at each new z_max).

    ``x``, ``n``, ``vel``, ``depth``: the element's position, normal, velocity and depth this substep (zeros for
    non-finite foot inputs); ``force``: its filtered force this substep, stored only in ``"ema"`` mode. Reads
    and writes element [w, f, p] only, so the thread that owns the element may call it after its own force
    evaluation has read the old state (no other thread touches the entry). Unchanged z_max, tau_r and anchors
    are not rewritten.
    """
    depth_max = state.depth_max[w, f, p]
    if rest.stick_distance > 0.0 and depth > 0.0:
        advance_stick_anchor(state.anchor, w, f, p, x, n, depth, depth_max, rest.stick_distance)
    new_depth_max = 0.0
    if depth > 0.0:
        new_depth_max = wp.max(depth_max, depth)
        if rest.footprint_radius > 0.0 and depth >= depth_max:
            state.footprint[w, f, p] = x  # where the element last reached z_max
    elif rest.footprint_radius > 0.0 and footprint_near(state.footprint[w, f, p], x, rest.footprint_radius):
        new_depth_max = depth_max  # footprint memory: z_max survives lift-off above the footprint
    if new_depth_max != depth_max:
        state.depth_max[w, f, p] = new_depth_max
    tau = state.ema_tau[w, f, p]
    new_tau = 0.0  # = ema_rigidity out of contact, without loading vel_prev (12 B) for emerged elements
    if depth > 0.0:
        new_tau = ema_rigidity(tau, vel, state.vel_prev[w, f, p], depth, rest.ema_rate, vertical_only)
    if new_tau != tau:
        state.ema_tau[w, f, p] = new_tau
    state.vel_prev[w, f, p] = vel
    if rest.mode == AT_REST_EMA:
        state.force_prev[w, f, p] = force


@wp.func
def advance_travel(state: ElementState, rest: AtRestParams, w: int, f: int, p: int, vel: wp.vec3, depth: float) -> None:
    """Advance element [w, f, p]'s travel memory past this substep; 0 out of the sand.

    Loosening (``RftExtensionsCfg.loosening_depth``, ``rest.loosening_dt`` > 0): the horizontal travel while
    submerged, + |v_xy| dt [m]. Erosion (``erosion_length``, ``rest.erosion_rate`` = dt / L_e > 0): the eroded share
    s [-], s + (1 - s) min(|v_xy| dt / L_e, 1), then times exp(-dz / ``rest.erosion_restore``) for a depth dz past
    z_max. Call it before :func:`advance_element_state` (it reads the old z_max). Nothing is read or written
    while both are off.
    """
    if rest.loosening_dt > 0.0:
        travel = 0.0
        if depth > 0.0:
            travel = state.travel[w, f, p] + wp.sqrt(vel[0] * vel[0] + vel[1] * vel[1]) * rest.loosening_dt
        state.travel[w, f, p] = travel
    elif rest.erosion_rate > 0.0:
        share = 0.0
        if depth > 0.0:
            share = state.travel[w, f, p]
            share += (1.0 - share) * wp.min(wp.sqrt(vel[0] * vel[0] + vel[1] * vel[1]) * rest.erosion_rate, 1.0)
            sink = depth - state.depth_max[w, f, p]
            if sink > 0.0:
                share *= wp.exp(-sink / rest.erosion_restore)
        state.travel[w, f, p] = share


def rft_element_model(model: Any) -> list:
    """Return the ``# Model:`` arguments the RFT element kernels share, in their order.

    Collider points, normals and areas, per-world rho_c, mu_int, mu_surf, the terrain, gravity [m/s^2], v_eps [m/s].
    """
    pts = [model.points_b, model.normals_b, model.areas]
    return [*pts, model.rho_c, model.mu_int, model.mu_surf, model.terrain, model.cfg.gravity, model.cfg.v_eps]


def point_kernel_data(model: Any, inputs: tuple) -> list:
    """Return the ``# Data in:`` arguments of the per-point force kernels: the foot pose, velocities and the state."""
    return [*inputs[:4], model.state]


@wp.kernel
def state_update_kernel(
    # Model:
    points_b: wp.array[wp.vec3],
    normals_b: wp.array[wp.vec3],
    terrain: TerrainData,
    rest: AtRestParams,
    vertical_only: int,
    # Data in:
    foot_pos_in: wp.array2d[wp.vec3],
    foot_mat_in: wp.array2d[wp.mat33],
    foot_lin_vel_in: wp.array2d[wp.vec3],
    foot_ang_vel_in: wp.array2d[wp.vec3],
    point_force_in: wp.array3d[wp.vec3],
    # Data out:
    state_out: ElementState,
) -> None:
    """Advance per-element memory: z_max (reset out of contact), EMA rigidity, previous velocity, stick anchor.

    Depth, position and velocity are recomputed from the foot kinematics with the functions the force kernels
    use (~35 flops per element, cheaper than reading stored values), so no element force is evaluated and the
    result does not depend on which compute() ran last. Non-finite foot inputs give depth 0 and velocity 0, as
    the force kernels store them. ``"ema"`` mode also stores ``point_force_in`` (this substep's filtered
    force); ``rest.stick_distance`` > 0 advances the anchors of submerged elements. Unchanged z_max, tau_r and
    anchors are not rewritten.
    """
    w, f, p = wp.tid()
    pos, rot, lin_vel, ang_vel, finite = read_foot_state(
        foot_pos_in, foot_mat_in, foot_lin_vel_in, foot_ang_vel_in, w, f
    )
    depth = 0.0
    x = wp.vec3(0.0)
    n = wp.vec3(0.0)
    vel = wp.vec3(0.0)
    if finite:
        kin = foot_point_kinematics(pos, rot, lin_vel, ang_vel, points_b[p], normals_b[p])
        x = kin[0]
        n = kin[1]
        vel = kin[2]
        depth = terrain_height(terrain, x[0], x[1]) - x[2]
    force = wp.vec3(0.0)
    if rest.mode == AT_REST_EMA:
        force = point_force_in[w, f, p]
    advance_travel(state_out, rest, w, f, p, vel, depth)  # before z_max moves
    advance_element_state(state_out, rest, vertical_only, w, f, p, x, n, vel, depth, force)


def eval_state_update(model: Any, inputs: tuple, vertical_only: int) -> None:
    """Launch :func:`state_update_kernel` over [num_worlds, num_feet, num_points] (no force pass)."""
    foot_pos, foot_mat, foot_lin_vel, foot_ang_vel, _ = inputs
    wp.launch(
        state_update_kernel,
        dim=model.point_depth.shape,
        inputs=[
            model.points_b,
            model.normals_b,
            model.terrain,
            model.rest,
            vertical_only,
            foot_pos,
            foot_mat,
            foot_lin_vel,
            foot_ang_vel,
            model.point_force,
        ],
        outputs=[model.state],
        device=model.device,
    )


@wp.kernel
def reset_state_kernel(
    # Data in:
    world_ids_in: wp.array[int],
    # Data out:
    state_out: ElementState,
) -> None:
    """Clear the per-element memory of the listed worlds."""
    i, f, p = wp.tid()
    w = world_ids_in[i]
    state_out.depth_max[w, f, p] = 0.0
    state_out.ema_tau[w, f, p] = 0.0
    state_out.force_prev[w, f, p] = wp.vec3(0.0)
    state_out.vel_prev[w, f, p] = wp.vec3(0.0)
    state_out.anchor[w, f, p] = wp.vec3(0.0)
    state_out.footprint[w, f, p] = wp.vec3(0.0)
    state_out.travel[w, f, p] = 0.0


def eval_reset_state(model: Any, world_ids: wp.array) -> None:
    """Launch :func:`reset_state_kernel` over [len(world_ids), num_feet, num_points]."""
    wp.launch(
        reset_state_kernel,
        dim=(world_ids.shape[0], model.num_feet, model.num_points),
        inputs=[world_ids],
        outputs=[model.state],
        device=model.device,
    )


@wp.kernel
def zero_wrench_kernel(
    # Data out:
    wrench_out: wp.array2d[wp.spatial_vector],
) -> None:
    """Write a zero wrench (rigid baseline: the simulator's own contact acts)."""
    w, f = wp.tid()
    wrench_out[w, f] = wp.spatial_vector(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def eval_zero_wrench(model: Any, wrench_out: wp.array) -> None:
    """Launch :func:`zero_wrench_kernel` over [num_worlds, num_feet]."""
    wp.launch(zero_wrench_kernel, dim=(model.num_worlds, model.num_feet), outputs=[wrench_out], device=model.device)
