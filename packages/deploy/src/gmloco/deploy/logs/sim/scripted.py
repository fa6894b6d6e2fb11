# SPDX-License-Identifier: Apache-2.0
"""A scripted standing/stepping joint-space controller for the G1 (no learning, no policy).

It exists to produce sample recordings before a trained policy does, and is labelled
``controller="scripted_stepping"`` in every recording. Gait: a phase clock alternates the legs; the swing leg
flexes hip, knee and ankle along a half-sine (foot lift); both hips and ankles roll to sway the pelvis over the
stance foot; the hips sweep fore and aft with a stride proportional to the commanded forward speed; the ankles
add pelvis roll/pitch feedback from the IMU. PD gains are stiffer than Unitree's RL deployment gains because
nothing else balances the robot.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gmloco.deploy.g1 import G1_FEET, G1_JOINT_NAMES, G1_KNEES_BENT_POSE, joint_index
from gmloco.deploy.logs.rotations import quat_to_rpy

__all__ = ["ScriptedStepping", "ScriptedSteppingCfg", "g1_knees_bent_pose"]


def g1_knees_bent_pose() -> np.ndarray:
    """Mjlab's ``KNEES_BENT_KEYFRAME`` joint pose [rad], canonical order, shape [29]."""
    return np.array(G1_KNEES_BENT_POSE)


def _gains(name: str) -> tuple[float, float]:
    """(kp [N*m/rad], kd [N*m*s/rad]) of a joint."""
    if "hip" in name or name == "waist_yaw_joint":
        return 200.0, 5.0
    if "knee" in name:
        return 300.0, 8.0
    if "ankle" in name:
        return 150.0, 4.0
    if "waist" in name:
        return 100.0, 3.0
    return 40.0, 1.0


@dataclass
class ScriptedSteppingCfg:
    """Settings of :class:`ScriptedStepping`."""

    default_pose: np.ndarray = field(default_factory=g1_knees_bent_pose)
    """Standing pose [rad], shape [29]."""
    kp: np.ndarray = field(default_factory=lambda: np.array([_gains(n)[0] for n in G1_JOINT_NAMES]))
    """Position gains [N*m/rad], shape [29]."""
    kd: np.ndarray = field(default_factory=lambda: np.array([_gains(n)[1] for n in G1_JOINT_NAMES]))
    """Velocity gains [N*m*s/rad], shape [29]."""
    stand_time: float = 1.0
    """Standing still before the first step [s]."""
    period: float = 0.8
    """Gait cycle (one step of each leg) [s]."""
    swing_fraction: float = 0.45
    """Fraction of a leg's cycle spent in swing [-]."""
    lift: float = 0.3
    """Peak swing flexion: hip and ankle pitch by -lift, knee by +2 lift [rad]."""
    sway: float = 0.06
    """Hip/ankle roll amplitude of the lateral sway [rad]."""
    sway_lead: float = 0.05
    """Phase lead of the sway over the swing [cycles], so weight shifts before lift-off."""
    leg_length: float = 0.6
    """Hip-to-sole length used to turn a stride into hip pitch [m]."""
    ankle_pitch_feedback: tuple[float, float] = (0.5, 0.05)
    """Ankle pitch target per pelvis pitch [rad/rad] and per pitch rate [rad/(rad/s)]."""
    ankle_roll_feedback: tuple[float, float] = (0.5, 0.05)
    """Ankle roll target per pelvis roll [rad/rad] and per roll rate [rad/(rad/s)], with opposite sign."""


class ScriptedStepping:
    """Joint targets from time, IMU and velocity command."""

    def __init__(self, cfg: ScriptedSteppingCfg | None = None) -> None:
        """Resolve joint indices."""
        self.cfg = cfg or ScriptedSteppingCfg()
        self._idx = {
            (foot, part): joint_index(f"{foot}_{part}_joint")
            for foot in G1_FEET
            for part in ("hip_pitch", "hip_roll", "knee", "ankle_pitch", "ankle_roll")
        }

    def targets(self, t: float, quat: np.ndarray, gyro: np.ndarray, lin_vel_x: float) -> np.ndarray:
        """Return joint position targets [rad], shape [29].

        Args:
            t: Time since start [s].
            quat: Pelvis IMU orientation (w, x, y, z).
            gyro: Pelvis angular velocity, IMU frame [rad/s].
            lin_vel_x: Commanded forward speed [m/s].
        """
        c, ix = self.cfg, self._idx
        q = c.default_pose.copy()
        roll, pitch, _ = quat_to_rpy(quat)
        walking = t >= c.stand_time
        phase = ((t - c.stand_time) / c.period) % 1.0
        shift = c.sway * np.sin(2 * np.pi * (phase + c.sway_lead)) if walking else 0.0
        stride = lin_vel_x * c.period / 2 / c.leg_length  # hip pitch half-sweep [rad]
        for foot, offset in zip(G1_FEET, (0.0, 0.5), strict=True):
            p = (phase - offset) % 1.0
            q[ix[foot, "hip_roll"]] += shift
            q[ix[foot, "ankle_roll"]] -= shift
            if walking and p < c.swing_fraction:
                h = np.sin(np.pi * p / c.swing_fraction)
                q[ix[foot, "hip_pitch"]] += -c.lift * h - stride * (2 * p / c.swing_fraction - 1)
                q[ix[foot, "knee"]] += 2 * c.lift * h
                q[ix[foot, "ankle_pitch"]] += -c.lift * h
            elif walking:
                s = (p - c.swing_fraction) / (1 - c.swing_fraction)
                q[ix[foot, "hip_pitch"]] += -stride * (1 - 2 * s)
            q[ix[foot, "ankle_pitch"]] += c.ankle_pitch_feedback[0] * pitch + c.ankle_pitch_feedback[1] * gyro[1]
            q[ix[foot, "ankle_roll"]] -= c.ankle_roll_feedback[0] * roll + c.ankle_roll_feedback[1] * gyro[0]
        return q
