# SPDX-License-Identifier: Apache-2.0
# Warp kernel DSL (``wp.tid()`` unpacking, array stores) is not typeable; see the pyright ``exclude`` note.
# pyright: reportIndexIssue=false, reportAssignmentType=false, reportGeneralTypeIssues=false
"""The per-element kernels' opening block (``kernels_foot``): read a foot, and leave an element of a bad one."""

from __future__ import annotations

import numpy as np
import warp as wp

from gmloco.contact.kernels_foot import read_foot_state, skip_element

DEVICE = "cpu"


@wp.kernel
def _opening_kernel(
    # Data in:
    foot_pos_in: wp.array2d[wp.vec3],
    foot_mat_in: wp.array2d[wp.mat33],
    foot_lin_vel_in: wp.array2d[wp.vec3],
    foot_ang_vel_in: wp.array2d[wp.vec3],
    # Data out:
    point_force_out: wp.array3d[wp.vec3],
    point_depth_out: wp.array3d[float],
    point_vel_out: wp.array3d[wp.vec3],
    nan_count_out: wp.array[int],
) -> None:
    """Write pos + lin_vel + ang_vel + rot e_x as the element's force, or skip a non-finite foot's element."""
    w, f, p = wp.tid()
    pos, rot, lin_vel, ang_vel, finite = read_foot_state(
        foot_pos_in, foot_mat_in, foot_lin_vel_in, foot_ang_vel_in, w, f
    )
    if not finite:
        skip_element(point_force_out, point_depth_out, point_vel_out, nan_count_out, w, f, p)
        return
    point_force_out[w, f, p] = pos + lin_vel + ang_vel + rot * wp.vec3(1.0, 0.0, 0.0)
    point_depth_out[w, f, p] = 1.0
    point_vel_out[w, f, p] = lin_vel


def test_finite_feet_are_read_and_bad_ones_skipped_per_element() -> None:
    """Foot [0, 1] has a NaN angular velocity: its 3 elements count 3 and get zeros; foot [0, 0] is read as given."""
    w, f, p = 1, 2, 3
    pos = np.array([[[0.1, 0.2, 0.3], [1.0, 1.0, 1.0]]], dtype=np.float32)
    rot = np.tile(np.eye(3, dtype=np.float32), (w, f, 1, 1))
    lin = np.full((w, f, 3), 0.5, dtype=np.float32)
    ang = np.zeros((w, f, 3), dtype=np.float32)
    ang[0, 1, 2] = np.nan
    force = wp.full((w, f, p), wp.vec3(7.0), dtype=wp.vec3, device=DEVICE)
    depth = wp.full((w, f, p), 7.0, dtype=float, device=DEVICE)
    vel = wp.full((w, f, p), wp.vec3(7.0), dtype=wp.vec3, device=DEVICE)
    count = wp.zeros(1, dtype=int, device=DEVICE)
    inputs = [
        wp.array(a, dtype=t, device=DEVICE)
        for a, t in ((pos, wp.vec3), (rot, wp.mat33), (lin, wp.vec3), (ang, wp.vec3))
    ]
    wp.launch(_opening_kernel, dim=(w, f, p), inputs=inputs, outputs=[force, depth, vel, count], device=DEVICE)
    # foot [0, 0]: pos + lin_vel + 0 + R e_x = (0.1 + 0.5 + 1, 0.2 + 0.5, 0.3 + 0.5)
    np.testing.assert_allclose(force.numpy()[0, 0], np.tile([1.6, 0.7, 0.8], (p, 1)), rtol=1e-6)
    np.testing.assert_allclose(depth.numpy()[0, 0], 1.0)
    np.testing.assert_allclose(force.numpy()[0, 1], 0.0)
    np.testing.assert_allclose(depth.numpy()[0, 1], 0.0)
    np.testing.assert_allclose(vel.numpy()[0, 1], 0.0)
    assert count.numpy()[0] == p
