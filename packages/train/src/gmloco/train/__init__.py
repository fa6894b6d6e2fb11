# SPDX-License-Identifier: Apache-2.0
"""gmloco.train: the Unitree G1 velocity task on granular terrain (mjlab 1.6), PPO training and evaluation.

Entry points:
    * :func:`train` with :class:`TrainRunCfg`: time-boxed, resumable PPO with ONNX export.
    * :func:`evaluate_policy` with :class:`EvalCfg`: roll out an exported ONNX policy in the granular simulator.
    * :func:`make_g1_granular_env_cfg` / :func:`g1_granular_task`: the mjlab env config factories.

The exports are resolved lazily (PEP 562): ``import gmloco.train.teacher_student`` or ``gmloco.train.config``
does not pay for importing the mjlab env stack (15-25 s on CPU); ``from gmloco.train import train`` imports
the defining module on first access.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gmloco.train.lazy_exports import lazy_exports

if TYPE_CHECKING:
    from gmloco.train.config import (
        ContactModelName,
        FootClearanceName,
        GranularTaskCfg,
        MaterialRangeCfg,
        RobotDrCfg,
        SandFloorCfg,
        SandTerrainCfg,
        TerrainName,
        deep_sand_terrain,
        flat_sand_terrain,
        rough_sand_terrain,
    )
    from gmloco.train.evaluation import EvalCfg, evaluate_policy
    from gmloco.train.tasks.g1_granular import g1_granular_task, make_g1_granular_env_cfg, make_g1_granular_ppo_cfg
    from gmloco.train.training import TrainRunCfg, train

_EXPORTS: dict[str, str] = {
    "ContactModelName": "gmloco.train.config",
    "FootClearanceName": "gmloco.train.config",
    "GranularTaskCfg": "gmloco.train.config",
    "MaterialRangeCfg": "gmloco.train.config",
    "RobotDrCfg": "gmloco.train.config",
    "SandFloorCfg": "gmloco.train.config",
    "SandTerrainCfg": "gmloco.train.config",
    "TerrainName": "gmloco.train.config",
    "deep_sand_terrain": "gmloco.train.config",
    "flat_sand_terrain": "gmloco.train.config",
    "rough_sand_terrain": "gmloco.train.config",
    "EvalCfg": "gmloco.train.evaluation",
    "evaluate_policy": "gmloco.train.evaluation",
    "g1_granular_task": "gmloco.train.tasks.g1_granular",
    "make_g1_granular_env_cfg": "gmloco.train.tasks.g1_granular",
    "make_g1_granular_ppo_cfg": "gmloco.train.tasks.g1_granular",
    "TrainRunCfg": "gmloco.train.training",
    "train": "gmloco.train.training",
}
"""Public name -> the module that defines it."""

__all__ = [
    "ContactModelName",
    "EvalCfg",
    "FootClearanceName",
    "GranularTaskCfg",
    "MaterialRangeCfg",
    "RobotDrCfg",
    "SandFloorCfg",
    "SandTerrainCfg",
    "TerrainName",
    "TrainRunCfg",
    "deep_sand_terrain",
    "evaluate_policy",
    "flat_sand_terrain",
    "g1_granular_task",
    "make_g1_granular_env_cfg",
    "make_g1_granular_ppo_cfg",
    "rough_sand_terrain",
    "train",
]


__getattr__, __dir__ = lazy_exports(globals(), _EXPORTS)
