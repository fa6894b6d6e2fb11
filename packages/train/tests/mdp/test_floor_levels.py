# SPDX-License-Identifier: Apache-2.0
"""Saved floor depths map back to the nearest level of a (possibly changed) floor-depth curriculum."""

from __future__ import annotations

import pytest
import torch

from gmloco.train.config import SandFloorCfg
from gmloco.train.sand import SandContact, floor_levels_for_depths


def test_depths_of_the_same_range_give_their_own_levels() -> None:
    """Depths written from levels of a range return exactly those levels."""
    floor = SandFloorCfg(depth_range=(0.0, 0.30), num_levels=10)
    levels = torch.arange(10)
    depths = levels.float() / 9 * 0.30
    assert torch.equal(floor_levels_for_depths(depths, floor), levels)


def test_a_changed_range_keeps_each_env_near_its_depth() -> None:
    """From 0-30 cm in 10 levels to 0-20 cm in 11 (2 cm steps): 3.33 cm -> level 2 (4 cm), 30 cm -> the top."""
    floor = SandFloorCfg(depth_range=(0.0, 0.20), num_levels=11)
    depths = torch.tensor([0.0, 0.30 / 9, 0.30 * 2 / 9, 0.30])
    levels = floor_levels_for_depths(depths, floor)
    assert levels.tolist() == [0, 2, 3, 10]
    reached = 0.20 * levels.float() / 10
    assert torch.all((reached - depths.clamp(max=0.20)).abs() <= 0.01 + 1e-6)


@pytest.mark.parametrize("floor", [SandFloorCfg(depth_range=(0.05, 0.05), num_levels=1), SandFloorCfg(num_levels=1)])
def test_a_single_level_floor_puts_every_env_at_level_0(floor: SandFloorCfg) -> None:
    """A fixed floor has only level 0."""
    assert floor_levels_for_depths(torch.tensor([0.0, 0.1, 0.3]), floor).tolist() == [0, 0, 0]


def _sand(floor: SandFloorCfg, num_envs: int) -> SandContact:
    """A SandContact with only what its checkpoint state needs (no env, no contact model)."""
    from types import SimpleNamespace

    sand = SandContact.__new__(SandContact)
    sand.task = SimpleNamespace(terrain=SimpleNamespace(floor=floor))  # type: ignore[assignment]
    sand.num_envs, sand.device = num_envs, "cpu"
    sand.floor_level = torch.zeros(num_envs, dtype=torch.long)
    return sand


def test_checkpoint_state_round_trips_into_a_changed_curriculum() -> None:
    """Saved under 0-30 cm in 10 levels, restored under 0-20 cm in 11: each env keeps (nearly) its floor depth."""
    old = _sand(SandFloorCfg(depth_range=(0.0, 0.30), num_levels=10), 4)
    old.floor_level.copy_(torch.tensor([0, 1, 2, 9]))
    state = old.state_dict()
    assert set(state) == {"floor_level", "floor_depth"}
    new = _sand(SandFloorCfg(depth_range=(0.0, 0.20), num_levels=11), 4)
    new.load_state_dict(state)
    assert new.floor_level.tolist() == [0, 2, 3, 10]


def test_an_older_checkpoints_bare_levels_and_another_env_count() -> None:
    """Levels without depths are taken as they are; a checkpoint of another env count leaves the drawn levels."""
    sand = _sand(SandFloorCfg(depth_range=(0.0, 0.20), num_levels=11), 3)
    sand.load_state_dict({"floor_level": torch.tensor([1, 0, 4])})
    assert sand.floor_level.tolist() == [1, 0, 4]
    sand.load_state_dict({"floor_level": torch.tensor([5, 5]), "floor_depth": torch.tensor([0.1, 0.1])})
    assert sand.floor_level.tolist() == [1, 0, 4]
