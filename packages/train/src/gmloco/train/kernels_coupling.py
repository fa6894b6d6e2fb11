# SPDX-License-Identifier: Apache-2.0
"""Warp kernels that move foot state out of, and granular wrenches into, MuJoCo Warp ``Data``.

Conventions (read from ``mujoco_warp/_src/sensor.py`` and ``support.py``, version 3.11):

* ``d.cvel[w, b]`` is a spatial velocity ``(angular, linear)`` whose linear part is the velocity of
  the point at ``d.subtree_com[w, body_rootid[b]]``, both in the world frame. The velocity of any
  point ``p`` rigidly attached to body ``b`` is ``lin + ang x (p - subtree_com[root])``.
* ``d.xfrc_applied[w, b]`` is ``(force, torque)`` in the world frame, torque about the body CoM
  ``d.xipos[w, b]`` (MuJoCo ``xfrc_applied`` layout).
"""

from __future__ import annotations

import warp as wp

__all__ = [
    "gather_foot_state",
    "launch_gather_foot_state",
    "launch_scatter_foot_wrench",
    "scatter_foot_wrench",
]


@wp.kernel
def gather_foot_state(
    # Model:
    body_rootid: wp.array[int],
    foot_bodyid: wp.array[int],
    # Data in:
    xpos_in: wp.array2d[wp.vec3],
    xmat_in: wp.array2d[wp.mat33],
    xipos_in: wp.array2d[wp.vec3],
    subtree_com_in: wp.array2d[wp.vec3],
    cvel_in: wp.array2d[wp.spatial_vector],
    # Data out:
    foot_pos_out: wp.array2d[wp.vec3],
    foot_mat_out: wp.array2d[wp.mat33],
    foot_lin_vel_out: wp.array2d[wp.vec3],
    foot_ang_vel_out: wp.array2d[wp.vec3],
    foot_com_out: wp.array2d[wp.vec3],
) -> None:
    """Copy pose, origin velocity and CoM of each foot body into ``[W, F]`` arrays."""
    worldid, footid = wp.tid()
    bodyid = foot_bodyid[footid]
    pos = xpos_in[worldid, bodyid]
    cvel = cvel_in[worldid, bodyid]
    ang = wp.spatial_top(cvel)
    lin_com = wp.spatial_bottom(cvel)
    # Shift the linear velocity from the root subtree CoM to the body origin.
    offset = pos - subtree_com_in[worldid, body_rootid[bodyid]]
    foot_pos_out[worldid, footid] = pos
    foot_mat_out[worldid, footid] = xmat_in[worldid, bodyid]
    foot_lin_vel_out[worldid, footid] = lin_com + wp.cross(ang, offset)
    foot_ang_vel_out[worldid, footid] = ang
    foot_com_out[worldid, footid] = xipos_in[worldid, bodyid]


@wp.kernel
def scatter_foot_wrench(
    # Model:
    foot_bodyid: wp.array[int],
    # Data in:
    wrench_in: wp.array2d[wp.spatial_vector],
    # Data out:
    xfrc_applied_out: wp.array2d[wp.spatial_vector],
) -> None:
    """Overwrite ``xfrc_applied`` of each foot body with its granular wrench."""
    worldid, footid = wp.tid()
    xfrc_applied_out[worldid, foot_bodyid[footid]] = wrench_in[worldid, footid]


def launch_gather_foot_state(m: object, d: object, foot_bodyid: wp.array, out: tuple[wp.array, ...]) -> None:
    """Launch :func:`gather_foot_state` over ``[nworld, num_feet]``.

    Args:
        m: MuJoCo Warp ``Model``.
        d: MuJoCo Warp ``Data``.
        foot_bodyid: Body ids of the feet, shape ``[F]``.
        out: ``(pos, mat, lin_vel, ang_vel, com)`` arrays, each shape ``[W, F]``.
    """
    wp.launch(
        gather_foot_state,
        dim=out[0].shape,
        inputs=[m.body_rootid, foot_bodyid, d.xpos, d.xmat, d.xipos, d.subtree_com, d.cvel],
        outputs=list(out),
        device=out[0].device,
    )


def launch_scatter_foot_wrench(d: object, foot_bodyid: wp.array, wrench: wp.array) -> None:
    """Launch :func:`scatter_foot_wrench` over ``[nworld, num_feet]``."""
    wp.launch(
        scatter_foot_wrench,
        dim=wrench.shape,
        inputs=[foot_bodyid, wrench],
        outputs=[d.xfrc_applied],
        device=wrench.device,
    )
