# SPDX-License-Identifier: Apache-2.0
"""Unitree G1 (29-DoF) joint vocabulary shared by the log schema, the reader and the analyses.

The order is the Unitree SDK motor index order of the 29-DoF G1 (``LowState_.motor_state[i]`` for
``i < 29``), which is also the joint order of the MJCF shipped with mjlab
(``mjlab/asset_zoo/robots/unitree_g1/xmls/g1.xml``, descended from MuJoCo Menagerie).
"""

from __future__ import annotations

__all__ = [
    "G1_FEET",
    "G1_JOINT_NAMES",
    "G1_LEG_JOINTS",
    "G1_NUM_JOINTS",
    "G1_NUM_MOTOR_SLOTS",
    "joint_index",
]

G1_JOINT_NAMES: tuple[str, ...] = (
    # 0-5: left leg
    "left_hip_pitch_joint",
    "left_hip_roll_joint",
    "left_hip_yaw_joint",
    "left_knee_joint",
    "left_ankle_pitch_joint",
    "left_ankle_roll_joint",
    # 6-11: right leg
    "right_hip_pitch_joint",
    "right_hip_roll_joint",
    "right_hip_yaw_joint",
    "right_knee_joint",
    "right_ankle_pitch_joint",
    "right_ankle_roll_joint",
    # 12-14: waist
    "waist_yaw_joint",
    "waist_roll_joint",
    "waist_pitch_joint",
    # 15-21: left arm
    "left_shoulder_pitch_joint",
    "left_shoulder_roll_joint",
    "left_shoulder_yaw_joint",
    "left_elbow_joint",
    "left_wrist_roll_joint",
    "left_wrist_pitch_joint",
    "left_wrist_yaw_joint",
    # 22-28: right arm
    "right_shoulder_pitch_joint",
    "right_shoulder_roll_joint",
    "right_shoulder_yaw_joint",
    "right_elbow_joint",
    "right_wrist_roll_joint",
    "right_wrist_pitch_joint",
    "right_wrist_yaw_joint",
)
"""Canonical joint order of every per-joint array in the schema and in the reader's output."""

G1_NUM_JOINTS: int = len(G1_JOINT_NAMES)
"""Number of actuated joints of the 29-DoF G1."""

G1_NUM_MOTOR_SLOTS: int = 35
"""Length of ``LowState_.motor_state`` / ``LowCmd_.motor_cmd`` in ``unitree_hg`` (slots 29-34 unused)."""

G1_FEET: tuple[str, ...] = ("left", "right")
"""Foot order of every per-foot array (contact flags, foot heights, stance masks)."""

G1_LEG_JOINTS: dict[str, tuple[str, ...]] = {
    foot: tuple(n for n in G1_JOINT_NAMES[:12] if n.startswith(foot)) for foot in G1_FEET
}
"""Leg joints per foot, hip to ankle."""


def joint_index(name: str) -> int:
    """Return the canonical index of a G1 joint name.

    Args:
        name: Joint name with the ``_joint`` suffix, e.g. ``"left_knee_joint"``.

    Raises:
        KeyError: If the name is not a G1 29-DoF joint.
    """
    try:
        return G1_JOINT_NAMES.index(name)
    except ValueError:
        raise KeyError(f"{name!r} is not a G1 29-DoF joint name; expected one of {G1_JOINT_NAMES}") from None
