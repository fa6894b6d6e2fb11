# SPDX-License-Identifier: Apache-2.0
"""The nominal G1 simulator of the mismatch tool: mjlab's MJCF, rotor armature, a soft ground plane.

Everything here imports ``mujoco`` lazily so that ``gmloco.deploy.mismatch`` stays importable without it.
The nominal model is deliberately plain: joint torques come from the logged PD commands (no MuJoCo
actuator dynamics), feet touch a compliant plane (MuJoCo soft contact, sand-like sinkage of a few mm),
all other collisions are off. Every candidate effect (:mod:`gmloco.deploy.mismatch.effects`) is a
parametric change of *this* model.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from gmloco.deploy import g1
from gmloco.deploy.g1 import g1_mjcf_path
from gmloco.deploy.logs.g1 import G1_JOINT_NAMES
from gmloco.deploy.mismatch.sand import SandCfg

__all__ = [
    "FIXED_BASE_HEIGHT",
    "G1_ARMATURE",
    "G1_EFFORT_LIMIT",
    "SOLE_POINTS",
    "G1SimCfg",
    "build_model",
    "drop_visual_meshes",
    "g1_mjcf_path",
]

G1_ARMATURE: np.ndarray = np.array(g1.G1_ARMATURE)
"""Nominal reflected rotor inertia per joint [kg*m^2], canonical order, shape [29] (``gmloco.deploy.g1``)."""
G1_EFFORT_LIMIT: np.ndarray = np.array(g1.G1_EFFORT_LIMIT)
"""Nominal torque limit per joint [N*m], canonical order, shape [29] (``gmloco.deploy.g1``)."""

# Sole sample points in the ankle-roll link frame [m]: a 4 x 2 grid under the seven foot capsules of the
# MJCF (capsules span x in [-0.054, 0.132], y in [-0.027, 0.027], centre z = -0.025, radius 0.01).
_SX = (-0.05, 0.01, 0.07, 0.125)
_SY = (-0.025, 0.025)
SOLE_POINTS: np.ndarray = np.array([[x, y, -0.035] for x in _SX for y in _SY])
"""Foot sole points used by terrain effects, ankle-roll frame [m], shape [8, 3]."""


@dataclass
class G1SimCfg:
    """Nominal simulator settings of the mismatch tool."""

    timestep: float = 0.002
    """Physics step [s]; one step per 500 Hz log sample by default."""
    ground_timeconst: float = 0.02
    """MuJoCo ``solref`` time constant of the foot-ground contact [s] (soft: a few mm of sinkage)."""
    ground_dampratio: float = 1.0
    """MuJoCo ``solref`` damping ratio of the foot-ground contact [-]."""
    foot_friction: float = 0.8
    """Sliding friction coefficient of the foot capsules on the ground [-]."""
    ground: Literal["plane", "sand"] = "plane"
    """Nominal ground: MuJoCo soft contact on a plane, or the project's 3D-RFT sand on the soles (then the feet
    have no MuJoCo contact; the replay applies the sand forces, :mod:`gmloco.deploy.mismatch.sand`)."""
    sand: SandCfg = field(default_factory=SandCfg)
    """Sand medium and RFT settings (``ground="sand"``)."""
    fixed_base: bool = False
    """Weld the pelvis to the world (a gantry or a stand): the floating-base joint is removed, so ``qpos`` and
    ``qvel`` hold the 29 joints only, the pelvis hangs at ``FIXED_BASE_HEIGHT`` (its pose is
    ``model.body_pos`` / ``body_quat`` of the pelvis, settable between steps) and the feet touch nothing."""

    visual_meshes: bool = True
    """Keep the MJCF's visual mesh geoms. They never collide (contype and conaffinity 0) and the bodies carry
    explicit inertials, so dropping them leaves the dynamics bit for bit unchanged, but their mesh BVH made
    ``mj_collision`` two thirds of ``mj_step1`` (the replay drops them, :func:`drop_visual_meshes`)."""


FIXED_BASE_HEIGHT = 1.5
"""Pelvis height of a fixed-base model [m]: the extended legs (0.75 m) clear the floor with any tilt."""


def drop_visual_meshes(spec: Any) -> None:
    """Delete every mesh geom that cannot collide, and every mesh left unused, from a ``mujoco.MjSpec``.

    Raises:
        ValueError: a mesh geom that can collide (nonzero contype or conaffinity) or that has no explicit
            body inertial behind it would change the dynamics if dropped.
    """
    import mujoco

    for g in [g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH]:
        if g.contype or g.conaffinity:
            raise ValueError(f"mesh geom {g.name!r} can collide; only visual meshes may be dropped")
        if not g.parent.explicitinertial:
            raise ValueError(f"body {g.parent.name!r} takes its inertia from geoms; its meshes must stay")
        spec.delete(g)
    used = {g.meshname for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH}
    for mesh in [m for m in spec.meshes if m.name not in used]:
        spec.delete(mesh)


def build_model(cfg: G1SimCfg | None = None, spec_edit: Any = None) -> Any:
    """Compile the nominal G1 model and return a ``mujoco.MjModel``.

    Args:
        cfg: Simulator settings.
        spec_edit: Optional callable ``f(spec)`` applied to the ``mujoco.MjSpec`` before compiling; the
            benchmark generator uses it to inject model edits without touching this module.
    """
    import mujoco

    cfg = cfg or G1SimCfg()
    spec = mujoco.MjSpec.from_file(str(g1_mjcf_path()))
    spec.option.timestep = cfg.timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_EULER
    floor = spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 0.05])
    floor.solref = [cfg.ground_timeconst, cfg.ground_dampratio]
    for g in spec.geoms:
        if g.name.endswith("_collision"):
            foot = "_foot" in g.name
            g.contype = 1 if foot and cfg.ground == "plane" and not cfg.fixed_base else 0
            g.conaffinity = 0  # feet collide with the floor only, never with each other
            if foot:
                g.condim = 3
                g.friction[0] = cfg.foot_friction
                g.solref = [cfg.ground_timeconst, cfg.ground_dampratio]
    floor.contype, floor.conaffinity = 0, 1
    for j in spec.joints:
        if j.name in G1_JOINT_NAMES:
            j.armature = g1.g1_actuator(j.name).armature
    if cfg.fixed_base:
        spec.delete(spec.joint("floating_base_joint"))
        spec.body("pelvis").pos = [0.0, 0.0, FIXED_BASE_HEIGHT]
    if spec_edit is not None:
        spec_edit(spec)
    if not cfg.visual_meshes:
        drop_visual_meshes(spec)
    model = spec.compile()
    names = tuple(model.joint(i).name for i in range(0 if cfg.fixed_base else 1, model.njnt))
    if names != G1_JOINT_NAMES:
        raise RuntimeError(f"MJCF joint order {names} differs from G1_JOINT_NAMES")
    return model
