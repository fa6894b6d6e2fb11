# SPDX-License-Identifier: Apache-2.0
"""Kinematic jump references of the G1: synthesis (profile + IK), derived signals, and the ``.npz`` file format.

A reference holds the whole-body configuration ``qpos`` (free base + 29 joints, MuJoCo order) at ``fps`` and the
signals the imitation task reads, all derived from ``qpos`` with the G1 MuJoCo model: joint and base velocities
(central differences), the sole-site positions, the CoM and the contact schedule.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import mujoco
import numpy as np

from gmloco.deploy.atomic_io import atomic_write
from gmloco.deploy.g1 import G1_FOOT_BODIES, G1_FOOT_SITES
from gmloco.train.tasks.g1_jump.ik import IkCfg, IkTargets, WholeBodyIk, load_g1_model, standing_qpos
from gmloco.train.tasks.g1_jump.profile import JumpProfile, JumpProfileCfg, make_jump_profile

__all__ = [
    "REFERENCE_DIR",
    "JumpReference",
    "JumpSynthesisCfg",
    "kinematic_signals",
    "load_reference",
    "reference_path",
    "save_reference",
    "synthesize_reference",
]

REFERENCE_DIR = Path(__file__).parent / "data"
"""Folder of the shipped references (``jump_<name>.npz``) and their ``manifest.json``."""


def reference_path(name: str) -> Path:
    """Path of the shipped reference ``name`` ("vertical" or "forward")."""
    return REFERENCE_DIR / f"jump_{name}.npz"


@dataclass
class JumpSynthesisCfg:
    """One reference: the CoM / foot profile, the pelvis lean and the IK settings."""

    profile: JumpProfileCfg
    """Timing and geometry of the jump."""
    pelvis_lean: float = 0.3
    """Forward pelvis pitch reached at the end of the crouch [rad]; held to the end of the landing with
    ``angular_momentum="zero"``, free from push-off to landing with ``"jump"``."""
    ik: IkCfg | None = None
    """IK settings; None: ``IkCfg()``."""
    waist_lean: float = 0.0
    """Waist pitch posture target at full lean [rad], following the pelvis lean's timing; negative keeps the
    torso more upright than the pelvis, shortening the lever of its weight about the waist."""
    angular_momentum: Literal["zero", "jump"] = "jump"
    """Angular momentum schedule of the IK. "jump": the momentum about the CoM is held at zero from the start of
    the push-off to the end of the landing with no pelvis task, so the whole trunk turns on the hips to balance
    the legs (the waist and arms are costlier in the weighted pseudo-inverse, ``IkCfg.weight_*``); before and
    after, the ground's moment about the CoM is free and the pelvis orientation is primary. "zero": held at
    zero throughout with the pelvis orientation in its null space, which turns the torso on the waist."""


@dataclass
class JumpReference:
    """A sampled jump; T samples at ``fps``."""

    name: str
    """Motion name."""
    fps: float
    """Sample rate [Hz]."""
    joint_names: tuple[str, ...]
    """Hinge joint names in ``qpos[7:]`` order."""
    qpos: np.ndarray
    """Base position [m], base quaternion (w, x, y, z) and joint positions [rad], shape [T, 36]."""
    qvel: np.ndarray
    """Base linear velocity (world) [m/s], angular velocity (base frame) [rad/s], joint velocities [rad/s], [T, 35]."""
    feet_pos: np.ndarray
    """Sole-site positions, left then right, world frame [m], shape [T, 2, 3]."""
    com: np.ndarray
    """Whole-body CoM [m], shape [T, 3]."""
    in_contact: np.ndarray
    """Feet on the ground, shape [T] (bool)."""
    t_takeoff: float
    """Take-off time [s]."""
    t_touchdown: float
    """Touch-down time [s]."""
    t_push_start: float
    """Start of the push-off [s]."""
    sole_height: float
    """Height of the sole sites above the ground when a foot stands flat [m]."""

    @property
    def duration(self) -> float:
        """Time of the last sample [s]."""
        return (self.qpos.shape[0] - 1) / self.fps

    @property
    def base_vel_world(self) -> np.ndarray:
        """Base angular velocity in the world frame [rad/s], shape [T, 3]."""
        out = np.zeros((self.qpos.shape[0], 3))
        for i, (q, w) in enumerate(zip(self.qpos[:, 3:7], self.qvel[:, 3:6], strict=True)):
            mujoco.mju_rotVecQuat(out[i], w, q)
        return out


def _sole_height(model: mujoco.MjModel, q: np.ndarray) -> float:
    """Height of the left sole site above the lowest point of the left foot's collision capsules [m]."""
    data = mujoco.MjData(model)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    foot = model.body(G1_FOOT_BODIES[0]).id
    lows = [
        data.geom_xpos[g, 2] - model.geom_size[g, 0]
        for g in range(model.ngeom)
        if model.geom_bodyid[g] == foot and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE
    ]
    if not lows:
        raise ValueError(f"the G1 model has no foot collision capsules on {G1_FOOT_BODIES[0]}")
    return float(data.site(G1_FOOT_SITES[0]).xpos[2] - min(lows))


def _standing_state(model: mujoco.MjModel) -> tuple[np.ndarray, float]:
    """Standing qpos with the soles on z = 0 and the sole-site height above the ground [m]."""
    q = standing_qpos(model)
    data = mujoco.MjData(model)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    sole = _sole_height(model, q)
    q[2] -= data.site(G1_FOOT_SITES[0]).xpos[2] - sole
    return q, sole


def _solve_frames(model: mujoco.MjModel, cfg: JumpSynthesisCfg, profile: JumpProfile) -> tuple[np.ndarray, float]:
    """IK of every frame of ``profile``; returns qpos [T, nq] and the largest task error [m].

    Zero angular momentum about the CoM over flight is what a ballistic body without rotation needs (no external
    moment acts about its CoM); over push-off and landing it puts the ground force through the CoM. Outside that
    window (``angular_momentum="jump"``) the slow crouch and recovery track the pelvis lean instead, and the
    recovery starts from the pelvis pitch the momentum task left.
    """
    q0, _ = _standing_state(model)
    ik = WholeBodyIk(model, cfg.ik or IkCfg())
    ik.set_state(q0)
    data = ik.data
    mujoco.mj_comPos(model, data)
    com0 = data.subtree_com[ik.pelvis].copy()
    feet0 = np.stack([data.site_xpos[s].copy() for s in ik.feet])
    out, worst, dt = np.zeros((profile.time.size, model.nq)), 0.0, 1.0 / cfg.profile.fps
    window = (profile.time >= profile.t_push_start) & (profile.time < profile.t_touchdown + cfg.profile.t_land)
    lean = cfg.pelvis_lean * profile.lean_fraction
    for i in range(profile.time.size):
        angmom: np.ndarray | None = np.zeros(3)
        pitch: float | None = float(lean[i])
        if cfg.angular_momentum == "jump":
            if window[i]:
                pitch = None
            elif i > 0 and window[i - 1]:
                # The recovery brings the pelvis from wherever the momentum task left it back upright.
                lean = lean.copy()
                lean[i:] = _pelvis_pitch(out[i - 1]) * profile.lean_fraction[i:]
                pitch = float(lean[i])
            if not window[i]:
                angmom = None
        targets = IkTargets(
            com=com0 + profile.com[i],
            feet=feet0 + profile.foot_offset[i],
            pelvis_pitch=pitch,
            angmom=angmom,
            dt=dt,
            waist_pitch=cfg.waist_lean * float(profile.lean_fraction[i]),
        )
        out[i] = ik.solve(targets)
        worst = max(worst, ik.last_error)
    return out, worst


def _pelvis_pitch(q: np.ndarray) -> float:
    """Pitch of the base about the world y axis [rad] (``atan2(R_02, R_22)``)."""
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, q[3:7])
    return float(np.arctan2(R[2], R[8]))


def _velocities(model: mujoco.MjModel, qpos: np.ndarray, fps: float) -> np.ndarray:
    """Central-difference generalized velocities (one-sided at the ends), shape [T, nv]."""
    T, dt = qpos.shape[0], 1.0 / fps
    qvel = np.zeros((T, model.nv))
    for i in range(T):
        a, b = max(i - 1, 0), min(i + 1, T - 1)
        mujoco.mj_differentiatePos(model, qvel[i], (b - a) * dt, qpos[a], qpos[b])
    return qvel


def kinematic_signals(model: mujoco.MjModel, qpos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sole-site positions [T, 2, 3] and CoM [T, 3] of every frame [m]."""
    data = mujoco.MjData(model)
    feet, com = np.zeros((qpos.shape[0], 2, 3)), np.zeros((qpos.shape[0], 3))
    pelvis = model.body("pelvis").id
    for i, q in enumerate(qpos):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        feet[i] = [data.site(n).xpos for n in G1_FOOT_SITES]
        com[i] = data.subtree_com[pelvis]
    return feet, com


def synthesize_reference(cfg: JumpSynthesisCfg, model: mujoco.MjModel | None = None) -> tuple[JumpReference, float]:
    """Build the reference of ``cfg``; returns it and the largest IK task error [m]."""
    g1: mujoco.MjModel = model if model is not None else load_g1_model()
    profile = make_jump_profile(cfg.profile)
    qpos, worst = _solve_frames(g1, cfg, profile)
    feet, com = kinematic_signals(g1, qpos)
    _, sole = _standing_state(g1)
    ref = JumpReference(
        name=cfg.profile.name,
        fps=cfg.profile.fps,
        joint_names=tuple(g1.joint(j).name for j in range(1, g1.njnt)),
        qpos=qpos,
        qvel=_velocities(g1, qpos, cfg.profile.fps),
        feet_pos=feet,
        com=com,
        in_contact=profile.in_contact,
        t_takeoff=profile.t_takeoff,
        t_touchdown=profile.t_touchdown,
        t_push_start=profile.t_push_start,
        sole_height=sole,
    )
    return ref, worst


def save_reference(ref: JumpReference, path: Path) -> None:
    """Write ``ref`` to ``path`` (compressed ``.npz``) atomically."""
    arrays = {
        "name": np.array(ref.name),
        "fps": np.array(ref.fps),
        "joint_names": np.array(ref.joint_names),
        "qpos": ref.qpos,
        "qvel": ref.qvel.astype(np.float32),
        "feet_pos": ref.feet_pos.astype(np.float32),
        "com": ref.com.astype(np.float32),
        "in_contact": ref.in_contact,
        "times": np.array([ref.t_push_start, ref.t_takeoff, ref.t_touchdown]),
        "sole_height": np.array(ref.sole_height),
    }
    atomic_write(path, lambda fh: np.savez_compressed(fh, **arrays))  # pyright: ignore[reportArgumentType]


def load_reference(path: str | Path) -> JumpReference:
    """Read a reference written by :func:`save_reference`.

    Raises:
        FileNotFoundError: If ``path`` does not exist (make one with ``python -m gmloco.train.tasks.g1_jump.make_reference``).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(
            f"no jump reference at {path}; write one with `python -m gmloco.train.tasks.g1_jump.make_reference`"
        )
    with np.load(path) as f:
        push, takeoff, touchdown = (float(v) for v in f["times"])
        return JumpReference(
            name=str(f["name"]),
            fps=float(f["fps"]),
            joint_names=tuple(str(n) for n in f["joint_names"]),
            qpos=f["qpos"].astype(np.float64),
            qvel=f["qvel"].astype(np.float64),
            feet_pos=f["feet_pos"].astype(np.float64),
            com=f["com"].astype(np.float64),
            in_contact=f["in_contact"].astype(bool),
            t_takeoff=takeoff,
            t_touchdown=touchdown,
            t_push_start=push,
            sole_height=float(f["sole_height"]),
        )
