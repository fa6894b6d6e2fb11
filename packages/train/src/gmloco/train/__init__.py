# SPDX-License-Identifier: Apache-2.0
"""gmloco.train: the Unitree G1 velocity task on granular terrain (mjlab 1.6), PPO training and evaluation.

Entry points:
    * :func:`train` with :class:`TrainRunCfg`: time-boxed, resumable PPO with ONNX export.
    * :func:`evaluate_policy` with :class:`EvalCfg`: roll out an exported ONNX policy in the granular simulator.
    * :func:`make_g1_granular_env_cfg` / :func:`g1_granular_task`: the mjlab env config factories.
"""

from gmloco.train.config import (
    ContactModelName,
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

__all__ = [
    "ContactModelName",
    "EvalCfg",
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
