# SPDX-License-Identifier: Apache-2.0
"""The mismatch stage's ``ground`` setting: plane, 3D-RFT sand, and a clear error for anything else."""

from __future__ import annotations

import pytest
from omegaconf import OmegaConf

from workflows import mismatch


def _section(ground: str) -> object:
    return OmegaConf.create({"ground": ground, "horizon": 30, "mirror_check": True, "effects": None, "n_boot": 10})


def test_plane_and_sand_grounds_give_different_replays() -> None:
    """``sand:poppy_seed`` builds a replay config that differs from the rigid-plane one."""
    plane = mismatch._analysis_cfg(_section("plane")).replay  # type: ignore[arg-type]
    sand = mismatch._analysis_cfg(_section("sand:poppy_seed")).replay  # type: ignore[arg-type]
    assert plane != sand


@pytest.mark.parametrize("ground", ["gravel", "plane:dry_sand"])
def test_unknown_ground_is_refused_with_the_accepted_values(ground: str) -> None:
    """A typo must not silently fall back to the rigid plane."""
    with pytest.raises(ValueError, match="use 'plane', 'sand'"):
        mismatch._analysis_cfg(_section(ground))  # type: ignore[arg-type]
