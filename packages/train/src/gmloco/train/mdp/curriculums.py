# SPDX-License-Identifier: Apache-2.0
"""Curricula: hard-floor depth levels (terrain) and linear reward-weight / std ramps."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import torch

from gmloco.train.sand import get_sand

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.managers.curriculum_manager import CurriculumTermCfg

__all__ = ["reward_ramp", "sand_floor_levels"]


def _level_moves(distance: torch.Tensor, commanded: torch.Tensor, promote_distance: float) -> torch.Tensor:
    """Return +1 (walked > ``promote_distance`` [m]), -1 (walked < half the commanded distance [m]) or 0.

    The rule is mjlab's ``terrain_levels_vel``.
    """
    up = distance > promote_distance
    down = (distance < 0.5 * commanded) & ~up
    return up.long() - down.long()


def _survival_moves(time_out: torch.Tensor, failed: torch.Tensor) -> torch.Tensor:
    """Return +1 (episode ran to its time limit), -1 (ended by a failure) or 0 (neither, e.g. a manual reset)."""
    up = time_out.bool()
    down = failed.bool() & ~up
    return up.long() - down.long()


def sand_floor_levels(
    env: ManagerBasedRlEnv, env_ids: torch.Tensor, command_name: str, promote_distance: float = 4.0
) -> dict[str, torch.Tensor]:
    """Lower the floor under envs that walked far (or survived) and raise it under envs that lagged (or fell).

    The rule is the floor's ``promotion`` (:class:`~gmloco.train.config.SandFloorCfg`).

    Runs at reset, before the :class:`~gmloco.train.sand.SandContact` event places the floors.

    Args:
        env: The environment.
        env_ids: Envs being reset.
        command_name: Velocity command term.
        promote_distance: Distance from the env origin that earns a deeper floor [m].

    Returns:
        Mean and max level for logging.
    """
    sand = get_sand(env)
    floor = sand.task.terrain.floor
    if floor.curriculum and env.common_step_counter > 0 and len(env_ids) > 0:
        if floor.promotion == "survival":
            terms = env.termination_manager
            moves = _survival_moves(terms.time_outs[env_ids], terms.terminated[env_ids])
        else:
            robot = env.scene["robot"]
            distance = torch.linalg.vector_norm(
                robot.data.root_link_pos_w[env_ids, :2] - env.scene.env_origins[env_ids, :2], dim=1
            )
            command = env.command_manager.get_command(command_name)
            assert command is not None
            commanded = torch.linalg.vector_norm(command[env_ids, :2], dim=1) * env.max_episode_length_s
            moves = _level_moves(distance, commanded, promote_distance)
        levels = sand.floor_level[env_ids] + moves
        sand.floor_level[env_ids] = levels.clamp(0, floor.num_levels - 1)
    levels = sand.floor_level.float()
    return {"mean": levels.mean(), "max": levels.max(), "depth_mean": sand.floor_depth.mean()}


class reward_ramp:  # noqa: N801 (mjlab term naming)
    """Ramp a reward term's weight and one std-like parameter linearly over env steps.

    ``value(step) = start + (end - start) * clamp(step / num_steps, 0, 1)``
    (GM-Loco: tracking weights 4 -> 8 and std sqrt(1.0) -> sqrt(0.1) over 15k x 24 steps).
    """

    def __init__(self, cfg: CurriculumTermCfg, env: ManagerBasedRlEnv) -> None:
        self.term_cfg = env.reward_manager.get_term_cfg(cfg.params["reward_name"])

    def __call__(
        self,
        env: ManagerBasedRlEnv,
        env_ids: torch.Tensor,
        reward_name: str,
        num_steps: int,
        weight: tuple[float, float] | None = None,
        param: tuple[str, float, float] | None = None,
    ) -> dict[str, Any]:
        """Set the weight / param for the current ``env.common_step_counter``."""
        del env_ids, reward_name
        frac = min(max(env.common_step_counter / max(num_steps, 1), 0.0), 1.0)
        out: dict[str, Any] = {}
        if weight is not None:
            self.term_cfg.weight = weight[0] + (weight[1] - weight[0]) * frac
            out["weight"] = torch.tensor(self.term_cfg.weight)
        if param is not None:
            name, start, end = param
            self.term_cfg.params[name] = start + (end - start) * frac
            out[name] = torch.tensor(self.term_cfg.params[name])
        return out
