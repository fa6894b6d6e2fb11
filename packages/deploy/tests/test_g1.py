# SPDX-License-Identifier: Apache-2.0
"""The G1 facts of :mod:`gmloco.deploy.g1` agree with mjlab's G1 model (where mjlab is installed)."""

from __future__ import annotations

import re
import subprocess
import sys

import numpy as np
import pytest

from gmloco.deploy.g1 import (
    G1_ACTUATORS,
    G1_ARMATURE,
    G1_DAMPING,
    G1_EFFORT_LIMIT,
    G1_FOOT_BODIES,
    G1_FOOT_SITES,
    G1_JOINT_NAMES,
    G1_KNEES_BENT_POSE,
    G1_SOLE_BOX_CENTER,
    G1_SOLE_BOX_HALF_EXTENTS,
    G1_STIFFNESS,
    G1_VELOCITY_LIMIT,
    g1_actuator,
    g1_mjcf_path,
    joint_index,
)


def test_table_hand_values() -> None:
    """Knee 139 N m, ankle 2 x 25 N m with twice the 5020 armature, wrist pitch 5 N m; unknown names raise."""
    assert G1_EFFORT_LIMIT[joint_index("left_knee_joint")] == 139.0
    assert G1_EFFORT_LIMIT[joint_index("right_ankle_roll_joint")] == 50.0
    assert G1_ARMATURE[joint_index("waist_pitch_joint")] == 2 * G1_ACTUATORS["5020"].armature
    assert G1_EFFORT_LIMIT[joint_index("left_wrist_pitch_joint")] == 5.0
    assert len(G1_VELOCITY_LIMIT) == len(G1_STIFFNESS) == len(G1_DAMPING) == 29
    with pytest.raises(KeyError, match="not a G1 29-DoF joint"):
        g1_actuator("left_toe_joint")


def _mjlab_actuator(actuators: tuple, name: str) -> object:
    """Return the one mjlab actuator config whose name patterns match ``name``."""
    hits = [a for a in actuators if any(re.fullmatch(e, name) for e in a.target_names_expr)]
    assert len(hits) == 1, name
    return hits[0]


def test_actuators_match_mjlab() -> None:
    """Armature, effort limit and PD gains per joint equal mjlab's G1 actuator configs (float64 round-off)."""
    pytest.importorskip("mjlab")
    from mjlab.asset_zoo.robots import get_g1_robot_cfg

    actuators = get_g1_robot_cfg().articulation.actuators  # type: ignore[union-attr]
    cfgs = [_mjlab_actuator(actuators, n) for n in G1_JOINT_NAMES]
    for field, ours in (
        ("armature", G1_ARMATURE),
        ("effort_limit", G1_EFFORT_LIMIT),
        ("stiffness", G1_STIFFNESS),
        ("damping", G1_DAMPING),
    ):
        np.testing.assert_allclose(ours, [getattr(c, field) for c in cfgs], rtol=1e-12, err_msg=field)


def test_velocity_limits_match_mjlab() -> None:
    """Each motor's speed limit equals mjlab's ``ElectricActuator`` (two-motor linkages keep the 5020's)."""
    pytest.importorskip("mjlab")
    from mjlab.asset_zoo.robots.unitree_g1 import g1_constants as c

    motors = {"7520_14": c.ACTUATOR_7520_14, "7520_22": c.ACTUATOR_7520_22, "5020": c.ACTUATOR_5020}
    motors |= {"5020x2": c.ACTUATOR_5020, "4010": c.ACTUATOR_4010}
    for key, motor in motors.items():
        assert G1_ACTUATORS[key].velocity_limit == motor.velocity_limit, key
        scale = 2.0 if key == "5020x2" else 1.0
        np.testing.assert_allclose(G1_ACTUATORS[key].armature, scale * motor.reflected_inertia, rtol=1e-12)


def test_mjcf_path_is_found_without_importing_mjlab() -> None:
    """g1_mjcf_path names mjlab's G1 MJCF file and leaves mjlab (torch, Warp) unimported."""
    pytest.importorskip("mjlab")
    code = "import sys; from gmloco.deploy.g1 import g1_mjcf_path as f; print(f().is_file(), 'mjlab' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["True", "False"]
    assert g1_mjcf_path().parts[-5:] == ("asset_zoo", "robots", "unitree_g1", "xmls", "g1.xml")


def test_joint_order_and_feet_match_the_mjcf() -> None:
    """The MJCF shipped with mjlab lists the joints in canonical order and has both foot bodies."""
    mujoco = pytest.importorskip("mujoco")

    try:
        path = g1_mjcf_path()
    except ImportError:
        pytest.skip("mjlab is not installed")
    model = mujoco.MjModel.from_xml_path(str(path))
    assert tuple(model.joint(i).name for i in range(1, model.njnt)) == G1_JOINT_NAMES
    for body in G1_FOOT_BODIES:
        assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body) >= 0, body


def test_sole_sites_and_box_match_the_foot_capsules() -> None:
    """Each sole site sits on its foot body; the sole box holds the axes of that foot's collision capsules.

    A capsule's axis runs from ``pos - R e_z h`` to ``pos + R e_z h`` in the body frame (R from ``geom_quat``, h the
    half length ``geom_size[1]``); both ends must lie within ``center +- half_extents`` (exact: the box is the
    capsules' x span [-0.054, 0.132] m widened by 2 mm).
    """
    mujoco = pytest.importorskip("mujoco")

    try:
        path = g1_mjcf_path()
    except ImportError:
        pytest.skip("mjlab is not installed")
    model = mujoco.MjModel.from_xml_path(str(path))
    lo = np.subtract(G1_SOLE_BOX_CENTER, G1_SOLE_BOX_HALF_EXTENTS)
    hi = np.add(G1_SOLE_BOX_CENTER, G1_SOLE_BOX_HALF_EXTENTS)
    for body, site in zip(G1_FOOT_BODIES, G1_FOOT_SITES, strict=True):
        b = model.body(body).id
        assert model.site_bodyid[model.site(site).id] == b, site
        capsules = [
            g
            for g in range(model.ngeom)
            if model.geom_bodyid[g] == b and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE
        ]
        assert capsules, body
        for g in capsules:
            rot = np.zeros(9)
            mujoco.mju_quat2Mat(rot, model.geom_quat[g])
            axis = rot.reshape(3, 3)[:, 2] * model.geom_size[g, 1]
            for end in (model.geom_pos[g] + axis, model.geom_pos[g] - axis):
                assert np.all(end >= lo) and np.all(end <= hi), (body, g, end)


def test_knees_bent_pose_matches_mjlab() -> None:
    """The default standing pose equals mjlab's ``KNEES_BENT_KEYFRAME`` joint by joint (zero where unlisted)."""
    pytest.importorskip("mjlab")
    from mjlab.asset_zoo.robots.unitree_g1.g1_constants import KNEES_BENT_KEYFRAME

    def angle(name: str) -> float:
        """Return the keyframe angle of a joint (its patterns are disjoint)."""
        hits = [v for k, v in (KNEES_BENT_KEYFRAME.joint_pos or {}).items() if re.fullmatch(k, name)]
        return float(hits[0]) if hits else 0.0

    assert [angle(n) for n in G1_JOINT_NAMES] == list(G1_KNEES_BENT_POSE)
