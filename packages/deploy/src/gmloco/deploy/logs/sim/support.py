# SPDX-License-Identifier: Apache-2.0
"""A virtual gantry: the simulated counterpart of the safety harness used in hardware stepping tests.

The scripted stepping controller is open loop apart from ankle posture feedback and cannot balance a G1 on its
own. The gantry applies a roll/pitch spring-damper torque to the pelvis (and optionally carries part of the
weight); it never acts on x, y or yaw, so forward progress and foot contacts come from the legs alone. Its gains
are written into the run metadata (``support``) so no recording hides it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from gmloco.deploy.logs.rotations import quat_to_rpy

__all__ = ["VirtualGantry", "VirtualGantryCfg"]


@dataclass
class VirtualGantryCfg:
    """Settings of :class:`VirtualGantry`."""

    enabled: bool = True
    """Apply the gantry at all."""
    stiffness: float = 400.0
    """Roll/pitch torque per radian of pelvis tilt [N*m/rad]."""
    damping: float = 40.0
    """Roll/pitch torque per pelvis angular rate [N*m*s/rad]."""
    weight_fraction: float = 0.0
    """Fraction of the robot's weight carried upward at the pelvis [-]."""

    def label(self) -> str:
        """Metadata label of this support."""
        if not self.enabled:
            return "none"
        return (
            f"virtual_gantry(roll_pitch_stiffness={self.stiffness} N*m/rad, damping={self.damping} N*m*s/rad, "
            f"weight_fraction={self.weight_fraction})"
        )


class VirtualGantry:
    """Applies the gantry wrench to the pelvis through ``data.xfrc_applied``."""

    def __init__(self, cfg: VirtualGantryCfg, model: Any) -> None:
        """Look up the pelvis and the robot mass."""
        self.cfg = cfg
        self._pelvis = model.body("pelvis").id
        self._weight = float(model.body_subtreemass[self._pelvis]) * float(-model.opt.gravity[2])

    def apply(self, data: Any) -> None:
        """Write the gantry wrench (world frame, about the pelvis CoM) for the next step."""
        f = data.xfrc_applied[self._pelvis]
        f[:] = 0.0
        if not self.cfg.enabled:
            return
        roll, pitch, _ = quat_to_rpy(data.qpos[3:7])
        omega_world = data.xmat[self._pelvis].reshape(3, 3) @ data.qvel[3:6]
        f[2] = self.cfg.weight_fraction * self._weight
        f[3] = -self.cfg.stiffness * roll - self.cfg.damping * omega_world[0]
        f[4] = -self.cfg.stiffness * pitch - self.cfg.damping * omega_world[1]
