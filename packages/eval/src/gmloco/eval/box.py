# SPDX-License-Identifier: Apache-2.0
"""The intruder of the box study: a rigid box launched onto sand (shared by the MPM and reduced-order sides)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

__all__ = ["BoxCfg", "box_lateral_variant", "box_size_variant"]


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
        """Initial CoM position [m], [3]: x = y = 0, bottom drop_height above z = 0."""
        return np.array([0.0, 0.0, self.drop_height + 0.5 * self.size[2]])

    @property
    def initial_quat_wxyz(self) -> np.ndarray:
        """Initial orientation, unit quaternion (w, x, y, z), [4]."""
        return np.array([math.cos(0.5 * self.yaw), 0.0, 0.0, math.sin(0.5 * self.yaw)])

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


def box_size_variant(box: BoxCfg | None = None, scale: float = 1.5) -> BoxCfg:
    """Return the box with its footprint (x, y) scaled by ``scale`` at the same mass (size-dependence check)."""
    b = box or BoxCfg()
    return replace(b, size=(b.size[0] * scale, b.size[1] * scale, b.size[2]))
