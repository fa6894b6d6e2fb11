# SPDX-License-Identifier: Apache-2.0
"""The per-element kernels' opening block (``kernels_foot``), through every per-element force kernel.

A foot with a non-finite pose or velocity leaves each of its elements through ``skip_element``: zero force,
depth and velocity, one count per element; a finite foot in the same launch is read by ``read_foot_state`` and
gets the force it gets alone.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest
import warp as wp

from gmloco.contact import (
    ContactConeMultiCfg,
    ContactConeSingleCfg,
    ContactHeuristicRFTCfg,
    ContactModelCfg,
    ContactRFT3DCfg,
    make_contact_model,
)

_spec = importlib.util.spec_from_file_location("contact_test_helpers", Path(__file__).with_name("helpers.py"))
assert _spec is not None and _spec.loader is not None
_helpers = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_helpers)

W, F = 3, 2


def _feet(bad: bool) -> tuple[wp.array, ...]:
    """Feet 2 cm deep, moving down at 0.3 m/s; with ``bad`` foot [1, 0] has a NaN angular velocity."""
    pos = np.zeros((W, F, 3))
    pos[..., 2] = -0.02
    rot = np.tile(np.eye(3), (W, F, 1, 1))
    lin = np.zeros((W, F, 3))
    lin[..., 2] = -0.3
    ang = np.zeros((W, F, 3))
    if bad:
        ang[1, 0, 2] = np.nan
    return _helpers.foot_arrays(pos, rot, lin, ang, pos.copy())


@pytest.mark.parametrize(
    "cfg",
    [ContactConeSingleCfg(), ContactConeMultiCfg(), ContactHeuristicRFTCfg(), ContactRFT3DCfg()],
    ids=["cone_single", "cone_multi", "heuristic_rft", "rft3d"],
)
def test_a_bad_foot_skips_its_elements_and_leaves_the_others(cfg: ContactModelCfg, device: str) -> None:
    """Per-point kernel (unfused path): bad foot all zeros and P counts; every other foot as in a clean launch."""
    outputs = []
    for bad in (False, True):
        model = make_contact_model(cfg, W, F, device)
        model.fused = False
        wrench = wp.zeros((W, F), dtype=wp.spatial_vector, device=device)  # type: ignore[arg-type]
        pos, rot, lin_vel, ang_vel, com = _feet(bad)
        model.compute(pos, rot, lin_vel, ang_vel, com, wrench)
        outputs.append([model.point_force.numpy(), model.point_depth.numpy(), model.point_vel.numpy()])
        assert model.nan_count.numpy()[0] == (model.num_points if bad else 0)
    clean, dirty = outputs
    assert np.abs(clean[0][1, 0]).max() > 0.0  # the foot is loaded when finite
    keep = np.ones((W, F), dtype=bool)
    keep[1, 0] = False
    for a, b in zip(clean, dirty, strict=True):
        np.testing.assert_array_equal(b[1, 0], 0.0)
        np.testing.assert_array_equal(b[keep], a[keep])
