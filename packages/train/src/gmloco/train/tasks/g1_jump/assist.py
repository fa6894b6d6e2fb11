# SPDX-License-Identifier: Apache-2.0
"""ZEST-style assistive wrench on the pelvis (Sleiman et al. 2026) and the curriculum that removes it.

The wrench is a PD law toward the reference base pose, ``F = s (kp e_p + kd e_v)``, ``T = s (kp_r e_R + kd_r e_w)``,
clipped in norm and scaled by ``s`` in [0, 1]. It is written into ``xfrc_applied`` of the pelvis before every
physics substep by :class:`AssistedJointPositionAction` (the joint-position action of the velocity task plus the
wrench), so the PD loop runs at the physics rate. :func:`assist_scale_curriculum` lowers ``s`` whenever the moving
success rate of finished episodes clears a threshold, until the policy jumps with ``s = 0``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import torch
from mjlab.envs.mdp.actions import JointPositionAction, JointPositionActionCfg
from mjlab.utils.lab_api.math import quat_box_minus

from gmloco.train.tasks.g1_jump.config import JumpAssistCfg

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv

__all__ = [
    "AssistState",
    "AssistedJointPositionAction",
    "AssistedJointPositionActionCfg",
    "assist_scale_curriculum",
    "assist_wrench",
    "get_assist",
    "judged_episodes",
]


def assist_wrench(
    cfg: JumpAssistCfg,
    scale: float | torch.Tensor,
    pos: torch.Tensor,
    quat: torch.Tensor,
    lin_vel: torch.Tensor,
    ang_vel: torch.Tensor,
    ref_pos: torch.Tensor,
    ref_quat: torch.Tensor,
    ref_lin_vel: torch.Tensor,
    ref_ang_vel: torch.Tensor,
) -> tuple[torch.Tensor, torch.Tensor]:
    """PD wrench toward the reference base state, world frame.

    Args:
        cfg: Gains and caps.
        scale: Assist scale s [-], a float or shape [N].
        pos: Base position [m], world frame, shape [N, 3].
        quat: Base orientation (w, x, y, z), shape [N, 4].
        lin_vel: Base linear velocity [m/s], world frame, shape [N, 3].
        ang_vel: Base angular velocity [rad/s], world frame, shape [N, 3].
        ref_pos: Reference base position [m], shape [N, 3].
        ref_quat: Reference base orientation, shape [N, 4].
        ref_lin_vel: Reference base linear velocity [m/s], shape [N, 3].
        ref_ang_vel: Reference base angular velocity [rad/s], shape [N, 3].

    Returns:
        Force [N] and torque [N m], each [N, 3].
    """
    force = cfg.kp_pos * (ref_pos - pos) + cfg.kd_pos * (ref_lin_vel - lin_vel)
    # quat_box_minus(q_ref, q) is the world-frame rotation vector from q to q_ref.
    torque = cfg.kp_rot * quat_box_minus(ref_quat, quat) + cfg.kd_rot * (ref_ang_vel - ang_vel)
    force = force * torch.clamp(cfg.max_force / force.norm(dim=-1, keepdim=True).clamp_min(1e-9), max=1.0)
    torque = torque * torch.clamp(cfg.max_torque / torque.norm(dim=-1, keepdim=True).clamp_min(1e-9), max=1.0)
    s = torch.as_tensor(scale, dtype=pos.dtype, device=pos.device)
    s = s.unsqueeze(-1) if s.dim() == 1 else s
    return s * force, s * torque


@dataclass
class AssistState:
    """Curriculum state of the assist, shared by all envs (saved in checkpoints)."""

    scale: float
    """Current assist scale s [-]."""
    success_rate: float = 0.0
    """Moving average of the fraction of finished episodes that ended without a failure [-]."""
    episodes_since_change: int = 0
    """Episodes finished since the scale last changed."""

    def state_dict(self) -> dict[str, float]:
        """Plain-dict form for checkpoints."""
        return {
            "scale": self.scale,
            "success_rate": self.success_rate,
            "episodes_since_change": float(self.episodes_since_change),
        }

    def load_state_dict(self, state: dict[str, float]) -> None:
        """Restore from :meth:`state_dict`."""
        self.scale = float(state["scale"])
        self.success_rate = float(state["success_rate"])
        self.episodes_since_change = int(state["episodes_since_change"])

    def update(self, cfg: JumpAssistCfg, successes: int, episodes: int, num_envs: int) -> None:
        """Fold ``successes`` of ``episodes`` finished episodes into the average; step the scale down if earned."""
        if episodes == 0 or not cfg.enabled:
            return
        w = cfg.success_ema
        self.success_rate = (1.0 - w) * self.success_rate + w * successes / episodes
        self.episodes_since_change += episodes
        judged = self.episodes_since_change >= cfg.min_episodes_per_env * num_envs
        if judged and self.success_rate >= cfg.success_threshold:
            self.scale = max(0.0, self.scale - cfg.scale_step)
            self.episodes_since_change = 0


def get_assist(env: ManagerBasedRlEnv) -> AssistState:
    """Return the env's assist state (created by :class:`AssistedJointPositionAction`)."""
    return env.jump_assist  # type: ignore[attr-defined]


@dataclass(kw_only=True)
class AssistedJointPositionActionCfg(JointPositionActionCfg):
    """Joint-position action that also applies the assistive wrench to ``body_name``."""

    assist: JumpAssistCfg
    """Gains, caps and curriculum of the wrench."""
    body_name: str = "pelvis"
    """Robot body that receives the wrench."""

    def build(self, env: ManagerBasedRlEnv) -> AssistedJointPositionAction:
        """Build the action term."""
        return AssistedJointPositionAction(self, env)


class AssistedJointPositionAction(JointPositionAction):
    """mjlab's joint-position action plus the assistive wrench, refreshed before every physics substep."""

    cfg: AssistedJointPositionActionCfg

    def __init__(self, cfg: AssistedJointPositionActionCfg, env: ManagerBasedRlEnv) -> None:
        super().__init__(cfg=cfg, env=env)
        self._env = env
        self._body_ids = self._entity.find_bodies((cfg.body_name,), preserve_order=True)[0]
        initial = cfg.assist.initial_scale if cfg.assist.enabled else 0.0
        self.state = AssistState(scale=initial)
        env.jump_assist = self.state  # type: ignore[attr-defined]
        self.last_force = torch.zeros(self.num_envs, 3, device=self.device)
        """Force applied at the last substep [N], world frame, [N, 3]."""
        self._applied = False

    def apply_actions(self) -> None:
        """Set the joint targets, then the wrench of the current base state."""
        super().apply_actions()
        if self.state.scale <= 0.0:
            if self._applied:  # clear the last wrench once (a Python flag: no device sync per substep)
                self._write(torch.zeros_like(self.last_force), torch.zeros_like(self.last_force))
                self._applied = False
            return
        from gmloco.train.tasks.g1_jump.command import get_jump

        jump, data = get_jump(self._env), self._entity.data
        force, torque = assist_wrench(
            self.cfg.assist,
            self.state.scale,
            data.root_link_pos_w,
            data.root_link_quat_w,
            data.root_link_lin_vel_w,
            data.root_link_ang_vel_w,
            jump.reference("base_pos"),
            jump.reference("base_quat"),
            jump.reference("base_lin_vel"),
            jump.reference("base_ang_vel"),
        )
        self._write(force, torque)
        self._applied = True

    def _write(self, force: torch.Tensor, torque: torch.Tensor) -> None:
        """Write the wrench into the pelvis ``xfrc_applied``."""
        self._entity.write_external_wrench_to_sim(force.unsqueeze(1), torque.unsqueeze(1), body_ids=self._body_ids)
        self.last_force = force


def judged_episodes(timed_out: torch.Tensor, start_time: torch.Tensor, t_takeoff: float) -> tuple[int, int]:
    """Successes and count of the finished episodes that contain the jump (started before ``t_takeoff`` [s]).

    Episodes that reference state initialization started after the take-off only land or stand; counting them
    would let the scale drop before the policy can take off.
    """
    jumped = start_time < t_takeoff
    return int((timed_out & jumped).sum().item()), int(jumped.sum().item())


def assist_scale_curriculum(env: ManagerBasedRlEnv, env_ids: torch.Tensor) -> dict[str, float]:
    """Curriculum term: count reset envs that timed out (success) against those that failed, update the scale.

    Runs at the start of each reset (before the envs are cleared), when ``termination_manager.time_outs`` still
    says how each finished episode ended.
    """
    from gmloco.train.tasks.g1_jump.command import get_jump

    jump = get_jump(env)
    state, cfg = get_assist(env), jump.cfg.task.assist
    if isinstance(env_ids, torch.Tensor) and env.common_step_counter > 0 and env_ids.numel() > 0:
        timed_out = env.termination_manager.time_outs[env_ids]
        successes, episodes = judged_episodes(timed_out, jump.start_time[env_ids], jump.ref.t_takeoff)
        state.update(cfg, successes, episodes, env.num_envs)
    return {"assist_scale": state.scale, "success_rate": state.success_rate}
