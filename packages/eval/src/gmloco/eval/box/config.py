# SPDX-License-Identifier: Apache-2.0
"""The intruder of the box study: a rigid box launched onto sand (shared by the MPM and reduced-order sides)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

__all__ = ["BoxCfg", "box_lateral_variant", "box_roll_variant", "box_size_variant"]


@dataclass(frozen=True)
class BoxCfg:
    """A uniform rigid box released above a flat free surface at z = 0 with a horizontal velocity.

    The default size 0.3 x 0.3 x 0.2 m is a project choice (GM-Loco does not state it): a 35 kg box of that size
    loads the sand at 3.8 kPa, about a standing G1 on one foot sole (343 N / 0.0152 m^2 = 22.6 kPa) divided by 6,
    large enough to span several MPM voxels at 2-5 cm resolution. :func:`box_size_variant` checks the dependence.
    """

    size: tuple[float, float, float] = (0.3, 0.3, 0.2)
    """Edge lengths along the box's x, y, z axes [m]."""
    mass: float = 35.0
    """Mass [kg] (the G1's)."""
    drop_height: float = 0.1
    """Initial gap between the box bottom and the free surface [m]."""
    velocity: tuple[float, float] = (1.0, 0.0)
    """Initial horizontal velocity (v_x, v_y) in the world frame [m/s]."""
    yaw: float = 0.0
    """Initial yaw of the box about world z [rad]; a non-zero yaw gives a velocity along the box's own y axis."""
    roll: float = 0.0
    """Initial roll of the box about its own x axis (after the yaw) [rad]: the bottom face tilts sideways."""
    duration: float = 1.0
    """Simulated time after release [s]."""

    @property
    def half_extents(self) -> np.ndarray:
        """Half edge lengths [m], [3]."""
        return 0.5 * np.asarray(self.size, dtype=np.float64)

    @property
    def inertia_diag(self) -> np.ndarray:
        """Principal moments of inertia about the CoM [kg m^2], [3]."""
        a, b, c = self.size
        return self.mass / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])

    @property
    def initial_pos(self) -> np.ndarray:
        """Initial CoM position [m], [3]: x = y = 0, lowest point drop_height above z = 0."""
        rot_z = self._rotation()[2]  # world z row of the box rotation
        return np.array([0.0, 0.0, self.drop_height + float(np.abs(rot_z) @ self.half_extents)])

    @property
    def initial_quat_wxyz(self) -> np.ndarray:
        """Initial orientation, unit quaternion (w, x, y, z), [4]: yaw about world z, then roll about box x."""
        cy, sy, cr, sr = (
            math.cos(0.5 * self.yaw),
            math.sin(0.5 * self.yaw),
            math.cos(0.5 * self.roll),
            math.sin(0.5 * self.roll),
        )
        return np.array([cy * cr, cy * sr, sy * sr, sy * cr])  # q_yaw * q_roll

    def _rotation(self) -> np.ndarray:
        """Initial rotation matrix R = R_z(yaw) R_x(roll), [3, 3]."""
        cy, sy, cr, sr = math.cos(self.yaw), math.sin(self.yaw), math.cos(self.roll), math.sin(self.roll)
        r_z = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
        r_x = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
        return r_z @ r_x

    @property
    def initial_velocity(self) -> np.ndarray:
        """Initial linear velocity [m/s], [3]."""
        return np.array([self.velocity[0], self.velocity[1], 0.0])


def box_lateral_variant(box: BoxCfg | None = None, yaw_deg: float = 30.0) -> BoxCfg:
    """Return the lateral-velocity variant: the box yawed by ``yaw_deg`` against its (world-x) velocity.

    Its velocity then has a component along the box's own y axis (sin 30 deg = 0.5 of the speed), and a force
    perpendicular to the motion appears only in models that resolve the faces' orientation (3D-RFT, MPM).
    """
    return replace(box or BoxCfg(), yaw=math.radians(yaw_deg))


def box_roll_variant(box: BoxCfg | None = None, roll_deg: float = 15.0) -> BoxCfg:
    """Return the box rolled by ``roll_deg`` about its x axis (its launch direction): a sideways-tilted bottom.

    3D-RFT gives a tilted leading face moving along x a force along y (spec 5.1 case I: G_y = -0.17 for a 30 deg
    tilt); the vertical-plane models (Heuristic-RFT, cones) cannot, so this variant isolates the lateral force.
    """
    return replace(box or BoxCfg(), roll=math.radians(roll_deg))


def box_size_variant(box: BoxCfg | None = None, scale: float = 1.5) -> BoxCfg:
    """Return the box with its footprint (x, y) scaled by ``scale`` at the same mass (size-dependence check)."""
    b = box or BoxCfg()
    return replace(b, size=(b.size[0] * scale, b.size[1] * scale, b.size[2]))
