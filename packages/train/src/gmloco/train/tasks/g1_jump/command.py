# SPDX-License-Identifier: Apache-2.0
"""The jump reference as an mjlab command term: per-env motion time, phase, reference state, RSI on reset.

Every env plays the reference from its own start time; after the last frame it holds that (standing) frame for
``hold_s``. The reference is anchored at the env origin. On reset the robot is written to the reference state at
the start time (reference state initialization, Peng et al. 2018), which is 0 or, with probability
``rsi_probability``, uniform over the motion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import torch
from mjlab.managers import CommandTerm, CommandTermCfg

from gmloco.deploy.g1 import G1_FOOT_SITES
from gmloco.train.tasks.g1_jump.reference import JumpReference, load_reference, reference_path

if TYPE_CHECKING:
    from mjlab.entity import Entity
    from mjlab.envs import ManagerBasedRlEnv

    from gmloco.train.tasks.g1_jump.config import JumpTaskCfg

__all__ = ["JUMP_COMMAND", "JumpReferenceCommand", "JumpReferenceCommandCfg", "ReferenceTensors", "get_jump"]

JUMP_COMMAND = "jump"
"""Name of the command term."""


def get_jump(env: ManagerBasedRlEnv) -> JumpReferenceCommand:
    """Return the env's jump command term."""
    return env.command_manager.get_term(JUMP_COMMAND)  # type: ignore[return-value]


class ReferenceTensors:
    """A :class:`JumpReference` on a torch device, joints in the robot's order, sampled by linear interpolation.

    Args:
        ref: The reference.
        joint_names: The robot's joint names (order of ``joint_pos``).
        device: Torch device.
    """

    def __init__(self, ref: JumpReference, joint_names: list[str] | tuple[str, ...], device: str) -> None:
        missing = sorted(set(joint_names) - set(ref.joint_names))
        if missing:
            raise ValueError(f"the jump reference has no joints {missing}; rebuild it with make_reference")
        order = [ref.joint_names.index(n) for n in joint_names]
        as_t = lambda a: torch.as_tensor(np.asarray(a), dtype=torch.float32, device=device)  # noqa: E731
        self.fps, self.duration, self.num_frames = ref.fps, ref.duration, ref.qpos.shape[0]
        self.t_takeoff, self.t_touchdown, self.t_push_start = ref.t_takeoff, ref.t_touchdown, ref.t_push_start
        self.base_pos = as_t(ref.qpos[:, :3])
        """[T, 3] base position [m] relative to the env origin."""
        self.base_quat = as_t(ref.qpos[:, 3:7])
        """[T, 4] base orientation (w, x, y, z)."""
        self.joint_pos = as_t(ref.qpos[:, 7:][:, order])
        """[T, J] joint positions [rad]."""
        self.base_lin_vel = as_t(ref.qvel[:, :3])
        """[T, 3] base linear velocity, world frame [m/s]."""
        self.base_ang_vel = as_t(ref.base_vel_world)
        """[T, 3] base angular velocity, world frame [rad/s]."""
        self.joint_vel = as_t(ref.qvel[:, 6:][:, order])
        """[T, J] joint velocities [rad/s]."""
        self.feet_pos = as_t(ref.feet_pos)
        """[T, 2, 3] sole-site positions [m] relative to the env origin."""
        self.in_contact = as_t(ref.in_contact)
        """[T] 1 where the feet are on the ground."""

    def _frames(self, t: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Bracketing frame indices and blend weight of times ``t`` [s] (clamped to the motion), each [N]."""
        f = torch.clamp(t * self.fps, 0.0, self.num_frames - 1.0)
        i0 = torch.floor(f).long().clamp(max=self.num_frames - 2)
        return i0, i0 + 1, f - i0

    def sample(self, name: str, t: torch.Tensor) -> torch.Tensor:
        """Linearly interpolated signal ``name`` at times ``t`` [s] (quaternions renormalized), [N, ...]."""
        data = getattr(self, name)
        i0, i1, w = self._frames(t)
        a, b = data[i0], data[i1]
        out = a + w.reshape(-1, *([1] * (a.dim() - 1))) * (b - a)
        if name == "base_quat":
            out = out / out.norm(dim=-1, keepdim=True)
        return out


@dataclass(kw_only=True)
class JumpReferenceCommandCfg(CommandTermCfg):
    """Config of :class:`JumpReferenceCommand` (resampled only on reset)."""

    task: JumpTaskCfg
    """The jump task (motion, hold time, RSI probability)."""
    entity_name: str = "robot"
    """Robot entity."""
    resampling_time_range: tuple[float, float] = (1.0e9, 1.0e9)
    """Never resampled by time: every episode plays the motion once."""

    def build(self, env: ManagerBasedRlEnv) -> JumpReferenceCommand:
        """Build the command term."""
        return JumpReferenceCommand(self, env)


class JumpReferenceCommand(CommandTerm):
    """Motion clock and reference state of every env; ``command`` is the phase as (sin, cos) of pi * phase."""

    cfg: JumpReferenceCommandCfg

    def __init__(self, cfg: JumpReferenceCommandCfg, env: ManagerBasedRlEnv) -> None:
        super().__init__(cfg, env)
        self.robot: Entity = env.scene[cfg.entity_name]
        ref = load_reference(reference_path(cfg.task.motion))
        self.ref = ReferenceTensors(ref, self.robot.joint_names, self.device)
        self.time = torch.zeros(self.num_envs, device=self.device)
        """Motion time of each env [s] (runs past the motion end during the hold)."""
        self.start_time = torch.zeros(self.num_envs, device=self.device)
        """Motion time the episode started at [s]."""
        self.origin = torch.zeros(self.num_envs, 3, device=self.device)
        """World position of the reference origin of each env [m]."""
        self._fresh = torch.zeros(self.num_envs, dtype=torch.bool, device=self.device)
        for key in ("error_base_pos", "error_joint_pos", "error_feet_pos"):
            self.metrics[key] = torch.zeros(self.num_envs, device=self.device)

    # Signals.

    @property
    def phase(self) -> torch.Tensor:
        """Motion progress in [0, 1] (1 during the hold) [-], shape [N]."""
        return torch.clamp(self.time / self.ref.duration, 0.0, 1.0)

    @property
    def command(self) -> torch.Tensor:
        """(sin, cos) of pi * phase, shape [N, 2]: distinct for every phase in [0, 1]."""
        angle = math.pi * self.phase
        return torch.stack([torch.sin(angle), torch.cos(angle)], dim=-1)

    def reference(self, name: str) -> torch.Tensor:
        """Reference signal ``name`` (see :class:`ReferenceTensors`) at each env's time, positions in world frame."""
        out = self.ref.sample(name, self.time)
        if name == "base_pos":
            return out + self.origin
        if name == "feet_pos":
            return out + self.origin.unsqueeze(1)
        if name in ("base_lin_vel", "base_ang_vel", "joint_vel") and self.ref.duration > 0:
            return out * (self.time <= self.ref.duration).float().unsqueeze(-1)  # the hold is still
        return out

    # CommandTerm interface.

    def _resample_command(self, env_ids: torch.Tensor) -> None:
        """Pick each reset env's start time and write the reference state there (RSI)."""
        n = len(env_ids)
        rsi = torch.rand(n, device=self.device) < self.cfg.task.rsi_probability
        start = torch.rand(n, device=self.device) * self.ref.duration * rsi.float()
        self.start_time[env_ids] = start
        self.time[env_ids] = start
        self._fresh[env_ids] = True
        self.origin[env_ids] = self._env.scene.env_origins[env_ids]
        self._write_reference_state(env_ids)

    def _write_reference_state(self, env_ids: torch.Tensor) -> None:
        """Write the reference root and joint state at each env's time (joints clipped to the soft limits)."""
        t = self.time[env_ids]
        sample = self.ref.sample
        root = torch.cat(
            [
                sample("base_pos", t) + self.origin[env_ids],
                sample("base_quat", t),
                sample("base_lin_vel", t),
                sample("base_ang_vel", t),
            ],
            dim=-1,
        )
        limits = self.robot.data.soft_joint_pos_limits[env_ids]
        joint_pos = torch.clamp(sample("joint_pos", t), limits[..., 0], limits[..., 1])
        self.robot.write_joint_state_to_sim(joint_pos, sample("joint_vel", t), env_ids=env_ids)
        self.robot.write_root_state_to_sim(root, env_ids=env_ids)

    def _update_command(self, env_ids: torch.Tensor | None) -> None:
        """Advance the motion clock of every env by one policy step, except envs auto-reset during this step."""
        if env_ids is not None:
            # Explicit reset() (dt = 0): the clock was set by _resample_command; the next step advances it.
            self._fresh[env_ids] = False
            return
        self.time += self._env.step_dt * (~self._fresh).float()
        self._fresh[:] = False

    def _update_metrics(self) -> None:
        """Base, joint and feet tracking errors (logged per episode)."""
        data = self.robot.data
        self.metrics["error_base_pos"] = (data.root_link_pos_w - self.reference("base_pos")).norm(dim=-1)
        self.metrics["error_joint_pos"] = (data.joint_pos - self.reference("joint_pos")).norm(dim=-1)
        feet = data.site_pos_w[:, self.feet_site_ids]
        self.metrics["error_feet_pos"] = (feet - self.reference("feet_pos")).norm(dim=-1).mean(dim=-1)

    @property
    def feet_site_ids(self) -> list[int]:
        """Robot-local ids of the two sole sites (left, right)."""
        if not hasattr(self, "_feet_site_ids"):
            self._feet_site_ids = self.robot.find_sites(G1_FOOT_SITES, preserve_order=True)[0]
        return self._feet_site_ids
