# SPDX-License-Identifier: Apache-2.0
"""Per-foot contact signals from the granular wrench plus the rigid floor contact.

Once foot-ground rigid contact is off, mjlab's contact sensor sees only the hard floor under the
sand; the granular force lives in ``xfrc_applied``. :class:`FootContactTracker` sums both, thresholds
``|F|`` (40 N in GM-Loco) and keeps the gait bookkeeping that rewards and the critic read: contact
state, air (swing) time, contact time, first contact, landing force, slip speed, foot height above
the sand surface and foot roll/pitch. It updates lazily, once per env step (keyed on
``env.common_step_counter``), so any number of terms can read it for the cost of one update.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import torch

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv

    from gmloco.train.contact_coupling import ContactCoupling

__all__ = ["FootContactTracker", "SurfaceHeightFn"]

SurfaceHeightFn = Callable[[torch.Tensor, torch.Tensor], torch.Tensor]
"""Sand free-surface height [m] at world (x, y) [m], any broadcastable shapes."""


class FootContactTracker:
    """Contact state of the two feet, shape ``[num_envs, 2]`` for every per-foot signal.

    Args:
        env: The environment.
        coupling: Granular coupling whose wrench is added to the rigid force; None for rigid contact.
        rigid_sensor_name: mjlab ``ContactSensor`` of foot-floor contact (net force, world frame).
        foot_site_names: Sites on the soles (left, right) whose height and velocity are tracked.
        foot_body_names: Foot bodies (left, right) whose orientation is tracked.
        threshold: Contact threshold on ``|F|`` [N].
        surface_height: Sand free-surface height function.
    """

    def __init__(
        self,
        env: ManagerBasedRlEnv,
        coupling: ContactCoupling | None,
        rigid_sensor_name: str,
        foot_site_names: tuple[str, str],
        foot_body_names: tuple[str, str],
        threshold: float,
        surface_height: SurfaceHeightFn,
    ) -> None:
        self.env = env
        self.coupling = coupling
        self.rigid_sensor_name = rigid_sensor_name
        self.threshold = threshold
        self.surface_height = surface_height
        robot = env.scene["robot"]
        self.robot = robot
        self.site_ids = robot.find_sites(foot_site_names, preserve_order=True)[0]
        self.body_ids = robot.find_bodies(foot_body_names, preserve_order=True)[0]
        shape = (env.num_envs, len(self.site_ids))
        zeros = lambda: torch.zeros(shape, device=env.device)  # noqa: E731
        self.force_w = torch.zeros((*shape, 3), device=env.device)
        """Total (granular + floor) force on each foot [N], world frame, [W, 2, 3]."""
        self.force_norm = zeros()
        """|force_w| [N], [W, 2]."""
        self.in_contact = torch.zeros(shape, dtype=torch.bool, device=env.device)
        """|F| > threshold, [W, 2]."""
        self.first_contact = torch.zeros_like(self.in_contact)
        """Contact began during the last env step, [W, 2]."""
        self.air_time = zeros()
        """Time since the foot left contact [s] (0 in contact), [W, 2]."""
        self.contact_time = zeros()
        """Time since the foot made contact [s] (0 in the air), [W, 2]."""
        self.last_air_time = zeros()
        """Duration of the swing that ended at the last touchdown [s], [W, 2]."""
        self.landing_force = zeros()
        """|F| at touchdown [N] (0 on other steps), [W, 2]."""
        self.height = zeros()
        """Sole-site height above the sand free surface [m] (negative: sunk), [W, 2]."""
        self.vel_w = torch.zeros((*shape, 3), device=env.device)
        """Sole-site linear velocity [m/s], world frame, [W, 2, 3]."""
        self.slip_speed = zeros()
        """Horizontal sole speed while in contact [m/s] (0 in the air), [W, 2]."""
        self.roll = zeros()
        """Foot roll [rad] (ZYX Euler of the foot body), [W, 2]."""
        self.pitch = zeros()
        """Foot pitch [rad] (ZYX Euler of the foot body), [W, 2]."""
        self.swing_peak = zeros()
        """Highest sole height of the current swing [m] (the current height while in contact), [W, 2]."""
        self.stance_low = zeros()
        """Lowest sole height of the current or, in the air, the last stance [m] (0 after a reset), [W, 2]."""
        self.last_swing_apex = zeros()
        """Highest sole height of the swing that ended at the last touchdown [m], [W, 2]."""
        self.last_swing_lift = zeros()
        """That swing's apex minus the lowest sole height of the stance before it [m]: how far the foot came out
        of its own footprint, [W, 2]."""
        self._updated_at = -1

    def update(self) -> FootContactTracker:
        """Refresh every signal once per env step; later calls in the same step return at once."""
        step = self.env.common_step_counter
        if step == self._updated_at:
            return self
        dt = self.env.step_dt if self._updated_at >= 0 else 0.0
        self._updated_at = step
        self._update_forces()
        self._update_timers(dt)
        self._update_kinematics()
        self._update_swing()
        return self

    def reset(self, env_ids: torch.Tensor) -> None:
        """Clear the timers and this step's signals of ``env_ids`` (episode start).

        The signals were refreshed from the state the episode ended in, which is non-finite when its physics
        diverged; the observations of the reset step read them, so they restart at zero until the next step.
        """
        for buf in (self.air_time, self.contact_time, self.last_air_time, self.landing_force, self.swing_peak,
                    self.stance_low, self.last_swing_apex, self.last_swing_lift, self.force_w, self.force_norm,
                    self.height, self.vel_w, self.slip_speed, self.roll, self.pitch):  # fmt: skip
            buf[env_ids] = 0.0
        self.in_contact[env_ids] = False
        self.first_contact[env_ids] = False

    def _update_forces(self) -> None:
        """Sum the rigid floor force and the granular force, then threshold."""
        # mjlab's net contact force is along the normal from primary (foot) to secondary (floor),
        # i.e. the force the foot exerts on the floor; the force on the foot is its negative.
        rigid = self.env.scene[self.rigid_sensor_name].data.force
        torch.neg(rigid, out=self.force_w)
        if self.coupling is not None:
            self.force_w.add_(self.coupling.foot_force_w)
        torch.linalg.vector_norm(self.force_w, dim=-1, out=self.force_norm)

    def _update_timers(self, dt: float) -> None:
        """Advance air/contact timers and detect touchdowns."""
        now = self.force_norm > self.threshold
        torch.logical_and(now, ~self.in_contact, out=self.first_contact)
        self.last_air_time.copy_(torch.where(self.first_contact, self.air_time + dt, self.last_air_time))
        self.air_time.copy_(torch.where(now, 0.0, self.air_time + dt))
        self.contact_time.copy_(torch.where(now, self.contact_time + dt, 0.0))
        torch.mul(self.force_norm, self.first_contact, out=self.landing_force)
        self.in_contact.copy_(now)

    def _update_kinematics(self) -> None:
        """Sole height above the surface, sole velocity, slip speed and foot roll/pitch."""
        data = self.robot.data
        pos = data.site_pos_w[:, self.site_ids]
        self.height.copy_(pos[..., 2] - self.surface_height(pos[..., 0], pos[..., 1]))
        self.vel_w.copy_(data.site_lin_vel_w[:, self.site_ids])
        torch.mul(torch.linalg.vector_norm(self.vel_w[..., :2], dim=-1), self.in_contact, out=self.slip_speed)
        # Third row of the body->world rotation: R[2, :] = (-sin p, cos p sin r, cos p cos r) (ZYX Euler).
        quat = data.body_link_quat_w[:, self.body_ids]
        w, x, y, z = quat.unbind(-1)
        r20 = 2.0 * (x * z - w * y)
        r21 = 2.0 * (y * z + w * x)
        r22 = 1.0 - 2.0 * (x * x + y * y)
        self.roll.copy_(torch.atan2(r21, r22))
        self.pitch.copy_(torch.asin(torch.clamp(-r20, -1.0, 1.0)))

    def _update_swing(self) -> None:
        """Swing apex and lift: at a touchdown, close the swing; in contact, track the stance's lowest point."""
        touchdown, contact, h = self.first_contact, self.in_contact, self.height
        self.last_swing_apex.copy_(torch.where(touchdown, self.swing_peak, self.last_swing_apex))
        self.last_swing_lift.copy_(torch.where(touchdown, self.swing_peak - self.stance_low, self.last_swing_lift))
        stance_low = torch.where(contact, torch.minimum(self.stance_low, h), self.stance_low)
        self.stance_low.copy_(torch.where(touchdown, h, stance_low))
        self.swing_peak.copy_(torch.where(contact, h, torch.maximum(self.swing_peak, h)))
