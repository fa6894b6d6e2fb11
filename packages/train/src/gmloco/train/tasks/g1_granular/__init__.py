# SPDX-License-Identifier: Apache-2.0
"""Unitree G1 velocity task on granular terrain."""

from gmloco.train.tasks.g1_granular.env_cfgs import g1_granular_task, make_g1_granular_env_cfg
from gmloco.train.tasks.g1_granular.rl_cfg import make_g1_granular_ppo_cfg

__all__ = ["g1_granular_task", "make_g1_granular_env_cfg", "make_g1_granular_ppo_cfg"]
