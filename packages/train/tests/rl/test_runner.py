# SPDX-License-Identifier: Apache-2.0
"""The runner's step-reward bound: healthy rewards pass unchanged, a blown-up world's are clamped."""

from __future__ import annotations

import torch

from gmloco.train.rl.runner import STEP_REWARD_LIMIT, bounded_step_reward


def test_healthy_step_rewards_pass_unchanged() -> None:
    """Rewards within the bound are returned as they are."""
    rewards = torch.tensor([-4.0, -19.9, 0.0, 0.37, 19.9])
    assert torch.equal(bounded_step_reward(rewards), rewards)


def test_blown_up_step_rewards_are_clamped() -> None:
    """A -1.8e11 step (seen on the deep floor) and a huge positive one end at the bound."""
    rewards = torch.tensor([-1.8e11, 3.0, 5e9])
    assert bounded_step_reward(rewards).tolist() == [-STEP_REWARD_LIMIT, 3.0, STEP_REWARD_LIMIT]


class _Owner:
    """A stand-in state owner (the sand's floor levels, the jump assist's scale)."""

    def __init__(self, value: float) -> None:
        self.value = value

    def state_dict(self) -> dict[str, float]:
        return {"value": self.value}

    def load_state_dict(self, state: dict[str, float]) -> None:
        self.value = state["value"]


def test_env_state_round_trips_through_a_checkpoint_dict() -> None:
    """Each owner the env has is saved under its name and restored into a fresh env's owner."""
    from types import SimpleNamespace

    from gmloco.train.rl.runner import env_state, restore_env_state

    saved = env_state(SimpleNamespace(sand=_Owner(3.0), jump_assist=_Owner(0.5)))
    assert saved == {"sand": {"value": 3.0}, "jump_assist": {"value": 0.5}}
    fresh = SimpleNamespace(sand=_Owner(0.0), jump_assist=_Owner(1.0))
    restore_env_state(fresh, saved)
    assert (fresh.sand.value, fresh.jump_assist.value) == (3.0, 0.5)
    walk = SimpleNamespace(sand=_Owner(0.0))  # no jump assist: its saved state is skipped
    restore_env_state(walk, saved)
    assert env_state(walk) == {"sand": {"value": 3.0}}


def test_older_checkpoints_floor_levels_still_restore() -> None:
    """A checkpoint that kept the levels as ``sand_floor_level`` restores them into the sand."""
    from types import SimpleNamespace

    from gmloco.train.rl.runner import restore_env_state

    class _Sand:
        floor_level = None

        def load_state_dict(self, state: dict[str, torch.Tensor]) -> None:
            self.floor_level = state["floor_level"]

    env = SimpleNamespace(sand=_Sand())
    restore_env_state(env, {"sand_floor_level": torch.tensor([1, 2, 3]), "env_state": {}})
    assert env.sand.floor_level.tolist() == [1, 2, 3]
