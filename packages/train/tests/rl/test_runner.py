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
