# SPDX-License-Identifier: Apache-2.0
"""Typed cells and failure rules of the granular-simulator evaluations (pure data: no torch, no mjlab).

:class:`MaterialCellsCfg` is also the pipeline's sweep and ablation evaluation settings (``workflows/schemas.py``):
a numeric field's valid range sits in its ``metadata`` (``ge`` / ``gt`` / ``le``), checked when a config is composed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from gmloco.train.config import SandFloorCfg

__all__ = ["MaterialCellsCfg", "RolloutCriteriaCfg"]


@dataclass
class RolloutCriteriaCfg:
    """Commands, cells and the paper's failure rules shared by the granular-simulator evaluations."""

    speeds: tuple[float, ...] = field(default=(1.0,), metadata={"gt": 0})
    """Commanded forward speeds [m/s]."""
    repeats: int = field(default=2, metadata={"ge": 1})
    """Envs per (material, speed) cell."""
    duration_s: float = field(default=10.0, metadata={"gt": 0})
    """Episode duration that counts as success [s]."""
    min_base_height: float = field(default=0.2, metadata={"ge": 0})
    """Failure: pelvis below this height above the sand [m]."""
    max_tilt: float = field(default=math.pi / 4, metadata={"gt": 0, "le": math.pi})
    """Failure: |roll| or |pitch| above this [rad]."""
    floor: SandFloorCfg = field(
        default_factory=lambda: SandFloorCfg(enabled=False, depth_range=(0.3, 0.3), num_levels=1, curriculum=False)
    )
    """Hard floor: off for the feet by default (GM-Loco play terrain), 30 cm down for other bodies."""


@dataclass
class MaterialCellsCfg(RolloutCriteriaCfg):
    """Cells on named material presets: every (material, speed) pair, ``repeats`` envs each, and the failure rules."""

    materials: tuple[str, ...] = ("dry_sand", "poppy_seed")
    """Material presets (``gmloco.contact.MATERIAL_PRESETS``)."""
