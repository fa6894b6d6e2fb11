# SPDX-License-Identifier: Apache-2.0
"""Numpy leg FK against MuJoCo C (oracle) and a closed-form clearance."""

from __future__ import annotations

import numpy as np
import pytest

from gmloco.deploy.g1 import g1_mjcf_path, joint_index
from gmloco.deploy.logs.analysis import G1LegKinematics, g1_model, sole_heights


def test_fk_matches_mujoco() -> None:
    """ankle_roll_link pose in the pelvis frame equals MuJoCo's mj_kinematics to float precision."""
    mujoco = pytest.importorskip("mujoco")
    try:
        model = mujoco.MjModel.from_xml_path(str(g1_mjcf_path()))
    except ImportError:
        pytest.skip("mjlab (G1 MJCF) not installed")
    data = mujoco.MjData(model)
    q = np.random.default_rng(1).uniform(-0.6, 0.6, (8, 29))
    for foot in ("left", "right"):
        pos, rot = G1LegKinematics(foot).foot_pose(q)
        body = model.body(f"{foot}_ankle_roll_link").id
        for i in range(len(q)):
            data.qpos[:] = 0
            data.qpos[3] = 1
            data.qpos[7:] = q[i]
            mujoco.mj_kinematics(model, data)
            np.testing.assert_allclose(pos[i], data.xpos[body] - data.xpos[1], atol=1e-12)
            np.testing.assert_allclose(rot[i], data.xmat[body].reshape(3, 3), atol=1e-12)


def test_zero_pose_feet_level_and_symmetric() -> None:
    """At q = 0 with the pelvis upright both soles are at the same height (the model is mirror-symmetric)."""
    h = sole_heights(np.zeros((1, 29)), np.array([[1.0, 0, 0, 0]]))
    np.testing.assert_allclose(h[0, 0], h[0, 1], atol=1e-6)


def test_hip_pitch_rotation_clearance_closed_form() -> None:
    """Rotating the left hip pitch by theta rotates the whole leg rigidly about the hip pitch axis (y).

    A sole point at (dx, dz) from the hip pitch joint moves to dz' = dz cos(theta) - dx sin(theta), so the
    lowest sole point rises by min(dz) - min(dz cos(theta) - dx sin(theta)) over the sole points.
    """
    theta = -0.5  # swing the leg forward
    leg = g1_model()["legs"]["left"]
    hip = np.array(leg["chain"][0]["pos"])  # hip pitch joint in the pelvis frame (identity body quat)
    q = np.zeros((2, 29))
    q[1, joint_index("left_hip_pitch_joint")] = theta
    pts = G1LegKinematics("left").sole_points_pelvis(q[:1])[0] - hip
    expected = (pts[:, 2] * np.cos(theta) - pts[:, 0] * np.sin(theta)).min() - pts[:, 2].min()
    h = sole_heights(q, np.tile([1.0, 0, 0, 0], (2, 1)))
    np.testing.assert_allclose(h[1, 0] - h[0, 0], expected, atol=1e-12)
    assert expected > 0.05  # a real lift, not a vacuous check
    np.testing.assert_allclose(h[1, 1], h[0, 1], atol=1e-15)  # the right foot did not move
