# SPDX-License-Identifier: Apache-2.0
"""Warp kernels of the rigid-body <-> implicit-MPM two-way coupling (impulse harvest, collider velocity hand-over)."""

from __future__ import annotations

import warp as wp

__all__ = [
    "accumulate_sand_wrench",
    "eval_body_sand_wrench",
    "eval_pd_joint_force",
    "eval_predict_body_velocity",
    "eval_rewind_body_velocity",
    "hand_over_velocity",
    "mean_of_two_wrenches",
]


@wp.kernel
def _body_sand_wrench(
    # Model:
    collider_body: wp.array[int],
    body_com: wp.array[wp.vec3],
    # Data in:
    inv_dt: float,
    node_collider_in: wp.array[int],
    node_impulse_in: wp.array[wp.vec3],
    node_pos_in: wp.array[wp.vec3],
    body_q_in: wp.array[wp.transform],
    # Data out:
    body_wrench_out: wp.array[wp.spatial_vector],
) -> None:
    """Sum collider-node impulses of the sand on each body into (force, torque about the CoM)."""
    i = wp.tid()
    cid = node_collider_in[i]
    if cid < 0 or cid >= collider_body.shape[0]:
        return
    b = collider_body[cid]
    if b < 0 or b >= body_wrench_out.shape[0]:  # static, or a body the rigid solver does not own (window walls)
        return
    # F = J / dt: the impulse the sand gave the collider over the MPM step
    f = node_impulse_in[i] * inv_dt
    com = wp.transform_point(body_q_in[b], body_com[b])
    wp.atomic_add(body_wrench_out, b, wp.spatial_vector(f, wp.cross(node_pos_in[i] - com, f)))


def eval_body_sand_wrench(
    collider_body: wp.array,
    body_com: wp.array,
    dt: float,
    impulses: tuple[wp.array, wp.array, wp.array],
    body_q: wp.array,
    body_wrench_out: wp.array,
) -> None:
    """Write each body's sand wrench [N, N m] from ``SolverImplicitMPM.collect_collider_impulses`` output.

    Args:
        collider_body: Collider -> body index (``solver.collider_body_index``), [C].
        body_com: Body CoM in the body frame [m], [B].
        dt: MPM step the impulses were accumulated over [s].
        impulses: (impulse [N s], position [m], collider id) per collider node.
        body_q: Body poses, [B].
        body_wrench_out: Output (force, torque about CoM) in world frame, [B]; zeroed first.
    """
    node_impulse, node_pos, node_collider = impulses
    body_wrench_out.zero_()
    wp.launch(
        _body_sand_wrench,
        dim=node_collider.shape[0],
        inputs=[collider_body, body_com, 1.0 / dt, node_collider, node_impulse, node_pos, body_q],
        outputs=[body_wrench_out],
        device=body_wrench_out.device,
    )


@wp.kernel
def _accumulate_wrench(
    # Data in:
    wrench_in: wp.array[wp.spatial_vector],
    # Data out:
    total_out: wp.array[wp.spatial_vector],
) -> None:
    """Add each body's wrench to its running sum."""
    b = wp.tid()
    total_out[b] = total_out[b] + wrench_in[b]


def accumulate_sand_wrench(wrench: wp.array, total: wp.array) -> None:
    """Add this frame's sand wrench [N, N m] to ``total`` (per body, [B]), so a log can read a mean over frames."""
    wp.launch(_accumulate_wrench, dim=wrench.shape[0], inputs=[wrench], outputs=[total], device=total.device)


@wp.kernel
def _mean_of_two_wrenches(
    # Data in:
    a_in: wp.array[wp.spatial_vector],
    b_in: wp.array[wp.spatial_vector],
    # Data out:
    mean_out: wp.array[wp.spatial_vector],
) -> None:
    """Each body's mean of two wrenches."""
    i = wp.tid()
    mean_out[i] = 0.5 * (a_in[i] + b_in[i])


def mean_of_two_wrenches(a: wp.array, b: wp.array, mean: wp.array) -> None:
    """Write the per-body mean of wrenches ``a`` and ``b`` [N, N m] into ``mean``, [B]."""
    wp.launch(_mean_of_two_wrenches, dim=a.shape[0], inputs=[a, b], outputs=[mean], device=mean.device)


@wp.kernel
def _rewind_body_velocity(
    # Model:
    body_inv_mass: wp.array[float],
    body_inv_inertia: wp.array[wp.mat33],
    # Data in:
    dt: float,
    body_q_in: wp.array[wp.transform],
    body_qd_in: wp.array[wp.spatial_vector],
    body_wrench_in: wp.array[wp.spatial_vector],
    # Data out:
    body_qd_out: wp.array[wp.spatial_vector],
) -> None:
    """Remove the lagged sand wrench's velocity change, so MPM re-solves the contact with the body's mass."""
    b = wp.tid()
    w = body_wrench_in[b]
    rot = wp.transform_get_rotation(body_q_in[b])
    dv = dt * body_inv_mass[b] * wp.spatial_top(w)
    dw = dt * wp.quat_rotate(rot, body_inv_inertia[b] * wp.quat_rotate_inv(rot, wp.spatial_bottom(w)))
    body_qd_out[b] = body_qd_in[b] - wp.spatial_vector(dv, dw)


def eval_rewind_body_velocity(
    body_inv_mass: wp.array,
    body_inv_inertia: wp.array,
    dt: float,
    body_q: wp.array,
    body_qd: wp.array,
    body_wrench: wp.array,
    body_qd_out: wp.array,
) -> None:
    """Write body velocities without the last frame's sand wrench: qd - dt M^-1 wrench (semi-implicit coupling)."""
    wp.launch(
        _rewind_body_velocity,
        dim=body_qd.shape[0],
        inputs=[body_inv_mass, body_inv_inertia, dt, body_q, body_qd, body_wrench],
        outputs=[body_qd_out],
        device=body_qd.device,
    )


@wp.kernel
def _predict_body_velocity(
    # Data in:
    gravity: wp.vec3,
    dt: float,
    body_qd_in: wp.array[wp.spatial_vector],
    # Data out:
    body_qd_out: wp.array[wp.spatial_vector],
) -> None:
    """Velocity a body would reach after one more frame of free fall: linear part + g dt, angular unchanged."""
    b = wp.tid()
    qd = body_qd_in[b]
    body_qd_out[b] = wp.spatial_vector(wp.spatial_top(qd) + gravity * dt, wp.spatial_bottom(qd))


def eval_predict_body_velocity(
    gravity: tuple[float, float, float],
    dt: float,
    body_qd: wp.array,
    body_qd_out: wp.array,
) -> None:
    """Write the collider velocity MPM should solve against: qd + (g dt, 0) (predicted hand-over).

    The impulse MPM returns is applied over the *next* frame, during which the body also falls under gravity; a
    body supported by the sand (a box, a stance foot carrying the robot) would reach this velocity without the
    sand, so MPM's contact solve ends it at the velocity the body really has after that frame.

    Args:
        gravity: Gravity [m/s^2].
        dt: Frame time [s].
        body_qd: Body (linear, angular) velocities [m/s, rad/s], [B].
        body_qd_out: Output velocities, [B] (may not alias ``body_qd``).
    """
    wp.launch(
        _predict_body_velocity,
        dim=body_qd.shape[0],
        inputs=[wp.vec3(*gravity), dt, body_qd],
        outputs=[body_qd_out],
        device=body_qd.device,
    )


def hand_over_velocity(
    scheme: str,
    gravity: tuple[float, float, float],
    inv_mass: wp.array,
    inv_inertia: wp.array,
    dt: float,
    body_q: wp.array,
    body_qd: wp.array,
    body_wrench: wp.array,
    body_qd_out: wp.array,
) -> None:
    """Write the collider velocities of the MPM step under coupling ``scheme`` (``MpmSolverCfg.velocity_handover``).

    Args:
        scheme: ``"predict"`` (:func:`eval_predict_body_velocity`), ``"rewind"`` (:func:`eval_rewind_body_velocity`)
            or ``"actual"`` (a copy).
        gravity: Gravity [m/s^2] (``"predict"``).
        inv_mass: Inverse mass MPM solves against [1/kg], [B] (``"rewind"``).
        inv_inertia: Inverse body-frame inertia [1/(kg m^2)], [B] (``"rewind"``).
        dt: Frame time [s].
        body_q: Body poses, [B].
        body_qd: Body velocities after the frame's rigid substeps, [B].
        body_wrench: The lagged sand wrench applied during those substeps, [B] (``"rewind"``).
        body_qd_out: Output: the velocities the MPM collider sees, [B].
    """
    if scheme == "predict":
        eval_predict_body_velocity(gravity, dt, body_qd, body_qd_out)
    elif scheme == "rewind":
        eval_rewind_body_velocity(inv_mass, inv_inertia, dt, body_q, body_qd, body_wrench, body_qd_out)
    elif scheme == "actual":
        wp.copy(body_qd_out, body_qd, count=body_qd.shape[0])
    else:
        raise ValueError(f"unknown velocity hand-over {scheme!r}: choose 'predict', 'rewind' or 'actual'")


@wp.kernel
def _pd_joint_force(
    # Model:
    kp: wp.array[float],
    kd: wp.array[float],
    q_idx: wp.array[int],
    qd_idx: wp.array[int],
    coords_per_robot: int,
    dofs_per_robot: int,
    # Data in:
    joint_q_in: wp.array[float],
    joint_qd_in: wp.array[float],
    target_in: wp.array2d[float],
    # Data out:
    joint_f_out: wp.array[float],
) -> None:
    """PD torque tau = kp (q* - q) - kd qd of actuated joint a of robot r (explicit, every physics step)."""
    r, a = wp.tid()
    qi = r * coords_per_robot + q_idx[a]
    di = r * dofs_per_robot + qd_idx[a]
    joint_f_out[di] = kp[a] * (target_in[r, a] - joint_q_in[qi]) - kd[a] * joint_qd_in[di]


def eval_pd_joint_force(
    kp: wp.array,
    kd: wp.array,
    q_idx: wp.array,
    qd_idx: wp.array,
    coords_per_robot: int,
    dofs_per_robot: int,
    joint_q: wp.array,
    joint_qd: wp.array,
    target: wp.array,
    joint_f_out: wp.array,
) -> None:
    """Write the PD torques [N m] of every robot's actuated joints into ``joint_f_out`` (other dofs untouched).

    Args:
        kp: Stiffness per actuated joint [N m/rad], [A].
        kd: Damping per actuated joint [N m s/rad], [A].
        q_idx: Coordinate index of each actuated joint within one robot, [A].
        qd_idx: Dof index of each actuated joint within one robot, [A].
        coords_per_robot: Joint coordinates per robot (robots stored one after another).
        dofs_per_robot: Joint dofs per robot.
        joint_q: Joint coordinates [m, rad], [R coords_per_robot].
        joint_qd: Joint velocities [m/s, rad/s], [R dofs_per_robot].
        target: Joint targets q* [rad], [R, A].
        joint_f_out: Generalized forces [N, N m], [R dofs_per_robot].
    """
    wp.launch(
        _pd_joint_force,
        dim=target.shape,
        inputs=[kp, kd, q_idx, qd_idx, coords_per_robot, dofs_per_robot, joint_q, joint_qd, target],
        outputs=[joint_f_out],
        device=joint_f_out.device,
    )
