# SPDX-License-Identifier: Apache-2.0
"""The G1 scene in MuJoCo C: the mjlab MJCF plus a floor, rotor armature and feet-only collisions."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gmloco.deploy.g1 import G1_EFFORT_LIMIT, G1_JOINT_NAMES, g1_actuator, g1_mjcf_path

__all__ = ["G1SceneCfg", "build_g1_model", "g1_effort_limits"]


def g1_effort_limits() -> np.ndarray:
    """Joint torque limits [N*m], canonical order, shape [29]."""
    return np.array(G1_EFFORT_LIMIT)


@dataclass
class G1SceneCfg:
    """Settings of the MuJoCo C G1 scene."""

    timestep: float = 0.002
    """Physics step [s]."""
    foot_friction: float = 0.6
    """Sliding friction of the foot capsules (mjlab's value)."""
    floor: bool = True
    """Add a rigid floor plane at z = 0 (disable for a granular ground model that supplies all foot forces)."""


def build_g1_model(cfg: G1SceneCfg | None = None) -> Any:
    """Compile the G1 scene and return a ``mujoco.MjModel``.

    Feet keep their capsules (condim 3); other collision geoms are disabled, as in mjlab's feet-only
    collision preset. Joint armature follows mjlab's actuator constants (:mod:`gmloco.deploy.g1`).
    """
    import mujoco

    cfg = cfg or G1SceneCfg()
    spec = mujoco.MjSpec.from_file(str(g1_mjcf_path()))
    spec.option.timestep = cfg.timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    if cfg.floor:
        spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 0.05])
    for g in spec.geoms:
        if g.name.endswith("_collision"):
            foot = "_foot" in g.name
            g.contype = g.conaffinity = 1 if foot else 0
            if foot:
                g.condim = 3
                g.friction[0] = cfg.foot_friction
    for j in spec.joints:
        if j.name in G1_JOINT_NAMES:
            j.armature = g1_actuator(j.name).armature
    model = spec.compile()
    names = tuple(model.joint(i).name for i in range(1, model.njnt))
    if names != G1_JOINT_NAMES:
        raise RuntimeError(f"MJCF joint order {names} differs from G1_JOINT_NAMES")
    return model
