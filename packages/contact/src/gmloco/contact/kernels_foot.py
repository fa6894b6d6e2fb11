# SPDX-License-Identifier: Apache-2.0
"""The opening block of the per-element kernels: read one foot's pose and velocities and check them.

Every per-element force kernel (jammed cone, Heuristic-RFT, 3D-RFT), the fused 3D-RFT kernel and the state update
open with :func:`read_foot_state`; the per-element force kernels leave an element of a non-finite foot through
:func:`skip_element`.
"""

from __future__ import annotations

import warp as wp

from gmloco.contact.kernels_geometry import foot_inputs_finite, write_element

__all__ = ["read_foot_state", "skip_element"]


@wp.func
def read_foot_state(  # noqa: ANN201 (returns the tuple vec3, mat33, vec3, vec3, bool; Warp infers it)
    foot_pos_in: wp.array2d[wp.vec3],
    foot_mat_in: wp.array2d[wp.mat33],
    foot_lin_vel_in: wp.array2d[wp.vec3],
    foot_ang_vel_in: wp.array2d[wp.vec3],
    w: int,
    f: int,
):
    """Return foot [w, f]'s position [m], rotation, linear [m/s] and angular [rad/s] velocity, and whether all are finite.

    The four reads and the check open every per-element kernel, the fused 3D-RFT kernel and the state update.
    """
    pos = foot_pos_in[w, f]
    rot = foot_mat_in[w, f]
    lin_vel = foot_lin_vel_in[w, f]
    ang_vel = foot_ang_vel_in[w, f]
    return pos, rot, lin_vel, ang_vel, foot_inputs_finite(pos, rot, lin_vel, ang_vel)


@wp.func
def skip_element(
    point_force_out: wp.array3d[wp.vec3],
    point_depth_out: wp.array3d[float],
    point_vel_out: wp.array3d[wp.vec3],
    nan_count_out: wp.array[int],
    w: int,
    f: int,
    p: int,
) -> None:
    """Count element [w, f, p] of a non-finite foot in ``nan_count_out``; write zero force, depth and velocity."""
    wp.atomic_add(nan_count_out, 0, 1)
    write_element(wp.vec3(0.0), 0.0, wp.vec3(0.0), point_force_out, point_depth_out, point_vel_out, w, f, p)
