# SPDX-License-Identifier: Apache-2.0
"""Sand terrains: the training-side surface height agrees with the contact model's; registry ids."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gmloco.train import deep_sand_terrain, flat_sand_terrain, rough_sand_terrain
from gmloco.train.contact_models import contact_terrain_cfg
from gmloco.train.sand import make_surface_height


@pytest.mark.parametrize("terrain", [flat_sand_terrain(), rough_sand_terrain(), deep_sand_terrain()])
def test_surface_height_matches_contact_terrain(terrain: object) -> None:
    """z_s(x, y) used for foot heights, base height and terminations equals ``gmloco.contact``'s terrain."""
    from gmloco.contact.terrain import terrain_height

    rng = np.random.default_rng(0)
    x, y = rng.uniform(-5.0, 5.0, (2, 64))
    ours = make_surface_height(terrain)(torch.tensor(x), torch.tensor(y)).numpy()  # type: ignore[arg-type]
    np.testing.assert_allclose(ours, terrain_height(contact_terrain_cfg(terrain), x, y), atol=1e-12)  # type: ignore[arg-type]


def test_deep_terrain_has_a_fixed_30_cm_bed() -> None:
    """The deep bed keeps its floor 0.30 m down at every level (no floor curriculum)."""
    floor = deep_sand_terrain().floor
    assert floor.depth_range == (0.30, 0.30) and not floor.curriculum


def test_registry_ids() -> None:
    """Every (granular model, terrain) pair, the rigid baseline and the default id are registered in mjlab.

    Five granular models (four of GM-Loco and the calibrated 3D-RFT) on three terrains, rigid on flat, the default.
    """
    from mjlab.tasks.registry import list_tasks, load_env_cfg

    from gmloco.train.tasks.registry import TASK_IDS

    assert len(TASK_IDS) == 5 * 3 + 2 and set(TASK_IDS) <= set(list_tasks())
    cfg = load_env_cfg("Gmloco-Velocity-Granular-G1")
    assert cfg.events["sand_contact"].params["task"].contact_model == "rft3d"
    assert cfg.decimation == 4 and cfg.sim.mujoco.timestep == pytest.approx(0.005)
