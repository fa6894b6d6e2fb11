# SPDX-License-Identifier: Apache-2.0
"""The Unitree G1 (29-DoF) in one place: joints, feet (bodies, sole sites, sole box), actuator table, MJCF path.

Pure Python, no dependency: every package (deploy's light core, contact, train, eval) may import it without
pulling mujoco, Warp, torch or mjlab. The joint order is the Unitree SDK motor index order of the 29-DoF G1
(``LowState_.motor_state[i]`` for ``i < 29``), which is also the joint order of the MJCF shipped with mjlab
(``mjlab/asset_zoo/robots/unitree_g1/xmls/g1.xml``, descended from MuJoCo Menagerie). The actuator values are
mjlab 1.6.0's (``asset_zoo/robots/unitree_g1/g1_constants.py``); ``tests/test_g1.py`` checks them against it.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from pathlib import Path

__all__ = [
    "G1_ACTUATORS",
    "G1_ARMATURE",
    "G1_DAMPING",
    "G1_EFFORT_LIMIT",
    "G1_FEET",
    "G1_FOOT_BODIES",
    "G1_FOOT_SITES",
    "G1_JOINT_NAMES",
    "G1_KNEES_BENT_POSE",
    "G1_LEG_JOINTS",
    "G1_NUM_JOINTS",
    "G1_NUM_MOTOR_SLOTS",
    "G1_SOLE_BOX_CENTER",
    "G1_SOLE_BOX_HALF_EXTENTS",
    "G1_STIFFNESS",
    "G1_VELOCITY_LIMIT",
    "G1Actuator",
    "g1_actuator",
    "g1_actuator_type",
    "g1_mjcf_path",
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
"""Canonical joint order of every per-joint array (log schema, reader, simulators, policy metadata)."""

G1_NUM_JOINTS: int = len(G1_JOINT_NAMES)
"""Number of actuated joints of the 29-DoF G1."""

G1_NUM_MOTOR_SLOTS: int = 35
"""Length of ``LowState_.motor_state`` / ``LowCmd_.motor_cmd`` in ``unitree_hg`` (slots 29-34 unused)."""

G1_FEET: tuple[str, ...] = ("left", "right")
"""Foot order of every per-foot array (contact flags, foot heights, stance masks)."""

G1_FOOT_BODIES: tuple[str, str] = ("left_ankle_roll_link", "right_ankle_roll_link")
"""MJCF bodies of the feet, in :data:`G1_FEET` order; they carry the sole and receive the granular wrench."""

G1_FOOT_SITES: tuple[str, str] = ("left_foot", "right_foot")
"""MJCF sole sites, in :data:`G1_FEET` order: on the foot bodies, 3.7 cm below the ankle-roll origin."""

G1_SOLE_BOX_CENTER: tuple[float, float, float] = (0.039, 0.0, -0.03)
"""Centre of a box covering each foot's MJCF collision capsules, in the foot body (ankle-roll-link) frame [m].

The capsules (radius 1 cm) run along x over [-0.054, 0.132] m at z = -0.025 m; the box spans x in
[-0.056, 0.134] m and z in [-0.04, -0.02] m (:data:`G1_SOLE_BOX_HALF_EXTENTS`).
"""
G1_SOLE_BOX_HALF_EXTENTS: tuple[float, float, float] = (0.095, 0.035, 0.01)
"""Half sizes of the sole box of :data:`G1_SOLE_BOX_CENTER` along x, y, z [m]."""

G1_LEG_JOINTS: dict[str, tuple[str, ...]] = {
    foot: tuple(n for n in G1_JOINT_NAMES[:12] if n.startswith(foot)) for foot in G1_FEET
}
"""Leg joints per foot, hip to ankle."""


def g1_mjcf_path() -> Path:
    """Return the path of the G1 MJCF (29 DoF) shipped with mjlab 1.6.0, found without importing mjlab.

    Raises:
        ImportError: If mjlab is not installed.
    """
    spec = importlib.util.find_spec("mjlab")  # locate only: importing mjlab pulls torch and Warp
    if spec is None or spec.origin is None:
        raise ImportError("mjlab is not installed; the G1 MJCF ships with mjlab 1.6.0 (uv sync the workspace)")
    return Path(spec.origin).parent / "asset_zoo/robots/unitree_g1/xmls/g1.xml"


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


@dataclass(frozen=True)
class G1Actuator:
    """One G1 actuator type (mjlab's ``ElectricActuator`` plus its position-actuator gains)."""

    armature: float
    """Reflected rotor inertia [kg m^2]."""
    effort_limit: float
    """Torque limit |tau| <= effort_limit [N m]."""
    velocity_limit: float
    """Joint speed limit [rad/s]."""

    @property
    def stiffness(self) -> float:
        """PD stiffness kp = armature omega_n^2 [N m/rad] (mjlab: 10 Hz natural frequency)."""
        return self.armature * _NATURAL_FREQ**2

    @property
    def damping(self) -> float:
        """PD damping kd = 2 zeta armature omega_n [N m s/rad] (mjlab: damping ratio zeta = 2)."""
        return 2.0 * _DAMPING_RATIO * self.armature * _NATURAL_FREQ


_NATURAL_FREQ = 10 * 2.0 * 3.1415926535  # mjlab's NATURAL_FREQ, 10 Hz [rad/s], with its truncated pi
_DAMPING_RATIO = 2.0  # mjlab's DAMPING_RATIO [-]
_ARMATURE_5020 = 0.003609725

G1_ACTUATORS: dict[str, G1Actuator] = {
    "7520_14": G1Actuator(armature=0.01017752004132231, effort_limit=88.0, velocity_limit=32.0),
    "7520_22": G1Actuator(armature=0.025101924999999997, effort_limit=139.0, velocity_limit=20.0),
    "5020": G1Actuator(armature=_ARMATURE_5020, effort_limit=25.0, velocity_limit=37.0),
    # Ankles and waist roll/pitch: 4-bar linkages driven by two 5020 motors; mjlab assumes a 1:1 linkage and
    # sums their armature and torque (and so their gains); the speed stays the 5020's.
    "5020x2": G1Actuator(armature=2 * _ARMATURE_5020, effort_limit=50.0, velocity_limit=37.0),
    "4010": G1Actuator(armature=0.00425, effort_limit=5.0, velocity_limit=22.0),
}
"""Actuator types of the G1 by motor (reflected inertia from mjlab's two-stage planetary formula)."""


def g1_actuator_type(joint: str) -> str:
    """Return the actuator type (key of :data:`G1_ACTUATORS`) driving a G1 joint (mjlab's grouping)."""
    if any(k in joint for k in ("hip_pitch", "hip_yaw", "waist_yaw")):
        return "7520_14"
    if any(k in joint for k in ("hip_roll", "knee")):
        return "7520_22"
    if any(k in joint for k in ("ankle", "waist_roll", "waist_pitch")):
        return "5020x2"
    if any(k in joint for k in ("wrist_pitch", "wrist_yaw")):
        return "4010"
    return "5020"


def g1_actuator(joint: str) -> G1Actuator:
    """Return the actuator driving a G1 joint.

    Raises:
        KeyError: If the name is not a G1 29-DoF joint.
    """
    return G1_ACTUATORS[g1_actuator_type(G1_JOINT_NAMES[joint_index(joint)])]


G1_ARMATURE: tuple[float, ...] = tuple(g1_actuator(n).armature for n in G1_JOINT_NAMES)
"""Reflected rotor inertia per joint [kg m^2], canonical order, length 29."""
G1_EFFORT_LIMIT: tuple[float, ...] = tuple(g1_actuator(n).effort_limit for n in G1_JOINT_NAMES)
"""Torque limit per joint [N m], canonical order, length 29."""
G1_VELOCITY_LIMIT: tuple[float, ...] = tuple(g1_actuator(n).velocity_limit for n in G1_JOINT_NAMES)
"""Speed limit per joint [rad/s], canonical order, length 29."""
G1_STIFFNESS: tuple[float, ...] = tuple(g1_actuator(n).stiffness for n in G1_JOINT_NAMES)
"""Nominal PD stiffness kp per joint [N m/rad] (mjlab's position actuators), canonical order, length 29."""
G1_DAMPING: tuple[float, ...] = tuple(g1_actuator(n).damping for n in G1_JOINT_NAMES)
"""Nominal PD damping kd per joint [N m s/rad] (mjlab's position actuators), canonical order, length 29."""


def _knees_bent_angle(joint: str) -> float:
    """Joint angle of mjlab's ``KNEES_BENT_KEYFRAME`` [rad] (its arms held away from the body by the roll)."""
    side, _, part = joint.partition("_")
    if side not in ("left", "right"):
        return 0.0
    if part == "shoulder_roll_joint":
        return 0.2 if side == "left" else -0.2
    pose = {"hip_pitch_joint": -0.312, "knee_joint": 0.669, "ankle_pitch_joint": -0.363, "elbow_joint": 0.6}
    return pose.get(part, 0.2 if part == "shoulder_pitch_joint" else 0.0)


G1_KNEES_BENT_POSE: tuple[float, ...] = tuple(_knees_bent_angle(n) for n in G1_JOINT_NAMES)
"""mjlab's knees-bent standing pose (``KNEES_BENT_KEYFRAME``, the G1 tasks' default pose) [rad], length 29."""
