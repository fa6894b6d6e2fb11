# SPDX-License-Identifier: Apache-2.0
"""The optional ``history`` observation group: the six actor terms over N steps, ``[num_envs, N, 96]``."""

from __future__ import annotations

import pytest
import torch

from gmloco.train import g1_granular_task, make_g1_granular_env_cfg
from gmloco.train.tasks.g1_granular.observations_cfg import ACTOR_TERMS, HISTORY_GROUP

NUM_JOINTS = 29
ACTOR_FRAME = 3 + 3 + 3 + 3 * NUM_JOINTS  # ang vel, gravity, command, q, dq, last action = 96
HISTORY = 50  # the student's N (1.0 s at 50 Hz)


def test_history_group_is_left_out_by_default() -> None:
    """Vanilla PPO envs carry no history group (its rollout buffer would hold N frames per step)."""
    assert HISTORY_GROUP not in make_g1_granular_env_cfg(g1_granular_task("rft3d"), 2).observations


def test_history_group_shape_order_and_current_frame(device: str) -> None:
    """[num_envs, 50, 96], actor terms in order; without noise its newest frame equals the actor frame."""
    from mjlab.envs import ManagerBasedRlEnv

    task = g1_granular_task("rft3d", play=True)  # play: no observation noise, so both groups read the same values
    task.policy_history_length = 1
    cfg = make_g1_granular_env_cfg(task, num_envs=2, history_length=HISTORY)
    env = ManagerBasedRlEnv(cfg=cfg, device=device)
    try:
        obs, _ = env.reset()
        for _ in range(3):
            obs, *_ = env.step(torch.zeros(2, NUM_JOINTS))
        assert tuple(env.observation_manager.active_terms[HISTORY_GROUP]) == ACTOR_TERMS
        history, actor, critic = obs[HISTORY_GROUP], obs["actor"], obs["critic"]
        assert (
            isinstance(history, torch.Tensor) and isinstance(actor, torch.Tensor) and isinstance(critic, torch.Tensor)
        )
        assert history.shape == (2, HISTORY, ACTOR_FRAME)
        torch.testing.assert_close(history[:, -1], actor, rtol=0.0, atol=0.0)
        # Oldest frames are back-filled with the first frame after the reset (mjlab CircularBuffer).
        torch.testing.assert_close(history[:, 0], history[:, 1], rtol=0.0, atol=0.0)
        assert critic.shape[-1] == ACTOR_FRAME + 16  # eta is still the critic's last column
    finally:
        env.close()


@pytest.mark.parametrize("length", [0, 3])
def test_history_group_is_optional_in_the_cfg(length: int) -> None:
    """history_length 0 leaves the group out; N > 0 keeps it unflattened with N frames."""
    groups = make_g1_granular_env_cfg(g1_granular_task("rigid"), 2, history_length=length).observations
    assert (HISTORY_GROUP in groups) == (length > 0)
    if length:
        assert groups[HISTORY_GROUP].history_length == length and not groups[HISTORY_GROUP].flatten_history_dim
