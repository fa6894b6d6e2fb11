# SPDX-License-Identifier: Apache-2.0
"""Simulator-side recording (MuJoCo C, imported lazily): G1 scene, ground contact, scripted controller, recorder."""

from gmloco.deploy.logs.sim.ground import GroundContact, RigidGround, RigidGroundCfg
from gmloco.deploy.logs.sim.recorder import MujocoG1Recorder
from gmloco.deploy.logs.sim.run import CommandSegment, ScriptedRunCfg, record_scripted_run
from gmloco.deploy.logs.sim.scene import G1SceneCfg, build_g1_model
from gmloco.deploy.logs.sim.scripted import ScriptedStepping, ScriptedSteppingCfg
from gmloco.deploy.logs.sim.support import VirtualGantry, VirtualGantryCfg

__all__ = [
    "CommandSegment",
    "G1SceneCfg",
    "GroundContact",
    "MujocoG1Recorder",
    "RigidGround",
    "RigidGroundCfg",
    "ScriptedRunCfg",
    "ScriptedStepping",
    "ScriptedSteppingCfg",
    "VirtualGantry",
    "VirtualGantryCfg",
    "build_g1_model",
    "record_scripted_run",
]
