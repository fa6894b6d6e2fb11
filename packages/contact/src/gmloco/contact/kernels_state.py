# SPDX-License-Identifier: Apache-2.0
"""At-rest regularization: elastic unloading depth, EMA filter, and the once-per-substep state update."""

from __future__ import annotations

from typing import Any

import warp as wp

from gmloco.contact.kernels_geometry import TerrainData, foot_inputs_finite, foot_point_kinematics, terrain_height

__all__ = [
    "AT_REST_CODES",
    "ema_filter",
    "ema_rigidity",
    "eval_reset_state",
    "eval_state_update",
    "eval_state_update_from_kinematics",
    "eval_zero_wrench",
    "impact_damping",
    "unloading_depth",
]

AT_REST_NONE = wp.constant(0)
AT_REST_UNLOADING = wp.constant(1)
AT_REST_EMA = wp.constant(2)
AT_REST_CODES: dict[str, int] = {"none": 0, "unloading": 1, "ema": 2}
"""Integer codes of the at-rest modes used by the kernels."""


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


@wp.kernel
def state_update_kernel(
    # Model:
    ema_rate: float,
    vertical_only: int,
    # Data in:
    point_depth_in: wp.array3d[float],
    point_vel_in: wp.array3d[wp.vec3],
    point_force_in: wp.array3d[wp.vec3],
    # Data out:
    depth_max_out: wp.array3d[float],
    ema_tau_out: wp.array3d[float],
    force_prev_out: wp.array3d[wp.vec3],
    vel_prev_out: wp.array3d[wp.vec3],
) -> None:
    """Advance per-element memory: z_max (reset out of contact), EMA rigidity, previous force and velocity."""
    w, f, p = wp.tid()
    depth = point_depth_in[w, f, p]
    vel = point_vel_in[w, f, p]
    if depth > 0.0:
        depth_max_out[w, f, p] = wp.max(depth_max_out[w, f, p], depth)
    else:
        depth_max_out[w, f, p] = 0.0
    ema_tau_out[w, f, p] = ema_rigidity(
        ema_tau_out[w, f, p], vel, vel_prev_out[w, f, p], depth, ema_rate, vertical_only
    )
    force_prev_out[w, f, p] = point_force_in[w, f, p]
    vel_prev_out[w, f, p] = vel


def eval_state_update(model: Any, ema_rate: float, vertical_only: int) -> None:
    """Launch :func:`state_update_kernel` over [num_worlds, num_feet, num_points] from the last compute()."""
    wp.launch(
        state_update_kernel,
        dim=model.point_depth.shape,
        inputs=[ema_rate, vertical_only, model.point_depth, model.point_vel, model.point_force],
        outputs=[model.depth_max, model.ema_tau, model.force_prev, model.vel_prev],
        device=model.device,
    )


@wp.kernel
def state_update_kinematic_kernel(
    # Model:
    points_b: wp.array[wp.vec3],
    terrain: TerrainData,
    ema_rate: float,
    vertical_only: int,
    # Data in:
    foot_pos_in: wp.array2d[wp.vec3],
    foot_mat_in: wp.array2d[wp.mat33],
    foot_lin_vel_in: wp.array2d[wp.vec3],
    foot_ang_vel_in: wp.array2d[wp.vec3],
    # Data out:
    depth_max_out: wp.array3d[float],
    ema_tau_out: wp.array3d[float],
    vel_prev_out: wp.array3d[wp.vec3],
) -> None:
    """Advance z_max, the EMA rigidity and the previous velocity as :func:`state_update_kernel` does.

    Depth and velocity are recomputed from the foot kinematics with the same functions the force kernels use
    (~30 flops per element, cheaper than reading 16 B of stored depth and velocity), so no element force is
    re-evaluated and the result does not depend on which compute() call ran last. Non-finite foot inputs give
    depth 0 and velocity 0, as the force kernels store them. Unchanged z_max / tau_r are not rewritten.
    """
    w, f, p = wp.tid()
    pos = foot_pos_in[w, f]
    rot = foot_mat_in[w, f]
    lin_vel = foot_lin_vel_in[w, f]
    ang_vel = foot_ang_vel_in[w, f]
    depth = 0.0
    vel = wp.vec3(0.0)
    if foot_inputs_finite(pos, rot, lin_vel, ang_vel):
        kin = foot_point_kinematics(pos, rot, lin_vel, ang_vel, points_b[p], wp.vec3(0.0, 0.0, -1.0))
        x = kin[0]
        vel = kin[2]
        depth = terrain_height(terrain, x[0], x[1]) - x[2]
    depth_max = depth_max_out[w, f, p]
    new_depth_max = 0.0
    if depth > 0.0:
        new_depth_max = wp.max(depth_max, depth)
    if new_depth_max != depth_max:
        depth_max_out[w, f, p] = new_depth_max
    tau = ema_tau_out[w, f, p]
    new_tau = ema_rigidity(tau, vel, vel_prev_out[w, f, p], depth, ema_rate, vertical_only)
    if new_tau != tau:
        ema_tau_out[w, f, p] = new_tau
    vel_prev_out[w, f, p] = vel


def eval_state_update_from_kinematics(model: Any, inputs: tuple, ema_rate: float, vertical_only: int) -> None:
    """Launch :func:`state_update_kinematic_kernel` over [num_worlds, num_feet, num_points] (no force pass)."""
    foot_pos, foot_mat, foot_lin_vel, foot_ang_vel, _ = inputs
    wp.launch(
        state_update_kinematic_kernel,
        dim=model.point_depth.shape,
        inputs=[model.points_b, model.terrain, ema_rate, vertical_only, foot_pos, foot_mat, foot_lin_vel, foot_ang_vel],
        outputs=[model.depth_max, model.ema_tau, model.vel_prev],
        device=model.device,
    )


@wp.kernel
def reset_state_kernel(
    # Data in:
    world_ids_in: wp.array[int],
    # Data out:
    depth_max_out: wp.array3d[float],
    ema_tau_out: wp.array3d[float],
    force_prev_out: wp.array3d[wp.vec3],
    vel_prev_out: wp.array3d[wp.vec3],
) -> None:
    """Clear the per-element memory of the listed worlds."""
    i, f, p = wp.tid()
    w = world_ids_in[i]
    depth_max_out[w, f, p] = 0.0
    ema_tau_out[w, f, p] = 0.0
    force_prev_out[w, f, p] = wp.vec3(0.0)
    vel_prev_out[w, f, p] = wp.vec3(0.0)


def eval_reset_state(model: Any, world_ids: wp.array) -> None:
    """Launch :func:`reset_state_kernel` over [len(world_ids), num_feet, num_points]."""
    wp.launch(
        reset_state_kernel,
        dim=(world_ids.shape[0], model.num_feet, model.num_points),
        inputs=[world_ids],
        outputs=[model.depth_max, model.ema_tau, model.force_prev, model.vel_prev],
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
