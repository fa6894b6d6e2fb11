# SPDX-License-Identifier: Apache-2.0
"""Dynamic plausibility of a kinematic jump on rigid ground: inverse dynamics of the G1 along the reference.

For every sample, ``mj_inverse`` gives the generalized force ``M(q) q'' + c(q, q')`` the motion needs. The six
free-base rows of it cannot come from the motors: in flight they must vanish (a ballistic body), in stance they are
the ground wrench, split between the two soles by the minimum-norm solution of ``J_c[:6]^T w = f_base``. The joint
rows minus ``J_c^T w`` are the motor torques. From these the report checks unilateral contact, the friction cone,
the centre of pressure under each sole, and the joint position, velocity and effort limits.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import mujoco
import numpy as np

from gmloco.deploy.g1 import G1_FOOT_BODIES, G1_FOOT_SITES
from gmloco.train.tasks.g1_jump.ik import g1_joint_limits
from gmloco.train.tasks.g1_jump.profile import GRAVITY
from gmloco.train.tasks.g1_jump.reference import JumpReference, kinematic_signals

__all__ = ["PlausibilityReport", "check_plausibility", "inverse_dynamics", "sole_extent"]


@dataclass
class PlausibilityReport:
    """Worst values of the plausibility checks over one reference (SI units)."""

    mass: float
    """Robot mass [kg]."""
    flight_com_acc_error: float
    """Largest |CoM acceleration - (0, 0, -g)| in flight, from second differences of the CoM [m/s^2]."""
    flight_base_force: float
    """Largest |unactuated base force| in flight (zero for a ballistic body) [N]."""
    flight_base_torque: float
    """Largest |unactuated base torque| in flight (rate of change of the angular momentum) [N m]."""
    min_normal_force: float
    """Smallest total vertical ground force in stance [N] (unilateral contact needs >= 0)."""
    peak_normal_force: float
    """Largest total vertical ground force [N]."""
    max_friction_ratio: float
    """Largest |F_xy| / F_z of a sole in stance, over samples where F_z > 5 % of m g [-]."""
    max_cop_excursion: float
    """Largest centre-of-pressure coordinate over the sole's half-extent (<= 1 inside the sole) [-]."""
    stance_foot_speed: float
    """Largest sole-site speed over stance samples whose neighbours are in stance too [m/s] (zero: feet stick)."""
    stance_foot_height_error: float
    """Largest |sole-site height - standing sole height| in stance [m]."""
    flight_min_foot_clearance: float
    """Smallest sole-site height above its standing height in flight [m] (>= 0: no foot below the ground)."""
    joint_limit_margin: float
    """Smallest distance of a joint to its range limits [rad] (>= 0 inside)."""
    max_velocity_ratio: float
    """Largest |q'| over the motor velocity limit [-]."""
    max_torque_ratio: float
    """Largest |tau| over the effort limit [-]."""
    peak_torque: dict[str, float]
    """Largest |tau| per joint [N m]."""
    effort_limit: dict[str, float]
    """Effort limit per joint [N m] (mjlab's G1 actuators)."""

    def to_dict(self) -> dict[str, object]:
        """Plain-dict form (JSON-ready)."""
        return asdict(self)


def _accelerations(model: mujoco.MjModel, ref: JumpReference) -> np.ndarray:
    """Central second differences of ``qpos`` (zero at the ends), shape [T, nv]."""
    T, dt = ref.qpos.shape[0], 1.0 / ref.fps
    qacc = np.zeros((T, model.nv))
    v_back, v_fwd = np.zeros(model.nv), np.zeros(model.nv)
    for i in range(1, T - 1):
        mujoco.mj_differentiatePos(model, v_back, dt, ref.qpos[i - 1], ref.qpos[i])
        mujoco.mj_differentiatePos(model, v_fwd, dt, ref.qpos[i], ref.qpos[i + 1])
        qacc[i] = (v_fwd - v_back) / dt
    return qacc


def inverse_dynamics(model: mujoco.MjModel, ref: JumpReference) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ground wrenches and motor torques along ``ref``.

    Returns:
        ``wrench`` [T, 2, 6] (force [N] and torque [N m] about each sole site, world frame, zero in flight),
        ``tau`` [T, 29] joint torques [N m], ``base_residual`` [T, 6] unactuated base force left over (all of it in
        flight, the part the soles cannot produce in stance).
    """
    data = mujoco.MjData(model)
    qacc = _accelerations(model, ref)
    sites = [model.site(n).id for n in G1_FOOT_SITES]
    T = ref.qpos.shape[0]
    wrench, tau, residual = np.zeros((T, 2, 6)), np.zeros((T, model.nv - 6)), np.zeros((T, 6))
    for i in range(T):
        data.qpos[:], data.qvel[:], data.qacc[:] = ref.qpos[i], ref.qvel[i], qacc[i]
        mujoco.mj_inverse(model, data)
        qfrc = data.qfrc_inverse.copy()
        if ref.in_contact[i]:
            jac = np.zeros((12, model.nv))
            for k, s in enumerate(sites):
                mujoco.mj_jacSite(model, data, jac[6 * k : 6 * k + 3], jac[6 * k + 3 : 6 * k + 6], s)
            w = np.linalg.lstsq(jac[:, :6].T, qfrc[:6], rcond=None)[0]
            wrench[i] = w.reshape(2, 6)
            qfrc = qfrc - jac.T @ w
        residual[i], tau[i] = qfrc[:6], qfrc[6:]
    return wrench, tau, residual


def sole_extent(model: mujoco.MjModel) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper (x, y) corners of the left sole's capsules in the sole-site frame [m], shape [2] each."""
    data = mujoco.MjData(model)
    data.qpos[3] = 1.0
    mujoco.mj_kinematics(model, data)
    site = model.site(G1_FOOT_SITES[0]).id
    foot = model.body(G1_FOOT_BODIES[0]).id
    origin, rot = data.site_xpos[site], data.site_xmat[site].reshape(3, 3)
    points = []
    for g in range(model.ngeom):
        if model.geom_bodyid[g] != foot or model.geom_type[g] != mujoco.mjtGeom.mjGEOM_CAPSULE:
            continue
        axis = data.geom_xmat[g].reshape(3, 3)[:, 2] * model.geom_size[g, 1]
        points += [data.geom_xpos[g] + axis, data.geom_xpos[g] - axis]
    local = (np.array(points) - origin) @ rot
    return local[:, :2].min(axis=0), local[:, :2].max(axis=0)


def _interior(mask: np.ndarray) -> np.ndarray:
    """Samples of ``mask`` whose three-point stencil lies entirely in ``mask``, shape [T] (bool)."""
    interior = mask.copy()
    interior[1:] &= mask[:-1]
    interior[:-1] &= mask[1:]
    interior[[0, -1]] = False
    return interior


def _cop_excursion(model: mujoco.MjModel, ref: JumpReference, wrench: np.ndarray, mass: float) -> float:
    """Largest CoP coordinate relative to the sole's half-extent, over loaded stance samples [-]."""
    lo, hi = sole_extent(model)
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    h = ref.sole_height
    worst = 0.0
    for i in np.flatnonzero(ref.in_contact):
        for k in range(2):
            f, m = wrench[i, k, :3], wrench[i, k, 3:]
            if f[2] < 0.05 * mass * GRAVITY:
                continue
            # Force at ground point p = site + (dx, dy, -h): m_x = dy F_z + h F_y, m_y = -dx F_z - h F_x.
            cop = np.array([(-m[1] - h * f[0]) / f[2], (m[0] - h * f[1]) / f[2]])
            worst = max(worst, float(np.max(np.abs(cop - centre) / half)))
    return worst


def check_plausibility(model: mujoco.MjModel, ref: JumpReference) -> PlausibilityReport:
    """Run every check on ``ref`` (a reference built on ``model``, which must have no ground or actuators)."""
    mass = float(model.body_subtreemass[model.body("pelvis").id])
    wrench, tau, residual = inverse_dynamics(model, ref)
    dt, stance, interior = 1.0 / ref.fps, ref.in_contact, _interior(~ref.in_contact)
    _, com = kinematic_signals(model, ref.qpos)  # from the float64 qpos, not the float32 copy in the file
    com_acc = np.zeros_like(com)
    com_acc[1:-1] = (com[2:] - 2.0 * com[1:-1] + com[:-2]) / dt**2
    fz = wrench[:, :, 2]
    loaded = stance[:, None] & (fz > 0.05 * mass * GRAVITY)
    friction = np.linalg.norm(wrench[:, :, :2], axis=-1) / np.where(loaded, fz, 1.0)
    feet_vel = np.gradient(ref.feet_pos, dt, axis=0)
    lower, upper = model.jnt_range[1:, 0], model.jnt_range[1:, 1]
    effort, velocity = g1_joint_limits(model)
    joints = ref.qpos[:, 7:]
    names = ref.joint_names
    peak = np.abs(tau).max(axis=0)
    return PlausibilityReport(
        mass=mass,
        flight_com_acc_error=float(np.abs(com_acc[interior] - [0.0, 0.0, -GRAVITY]).max()),
        flight_base_force=float(np.linalg.norm(residual[interior, :3], axis=-1).max()),
        flight_base_torque=float(np.linalg.norm(residual[interior, 3:], axis=-1).max()),
        min_normal_force=float(fz[stance].sum(axis=-1).min()),
        peak_normal_force=float(fz.sum(axis=-1).max()),
        max_friction_ratio=float(np.where(loaded, friction, 0.0).max()),
        max_cop_excursion=_cop_excursion(model, ref, wrench, mass),
        stance_foot_speed=float(np.linalg.norm(feet_vel[_interior(stance)], axis=-1).max()),
        stance_foot_height_error=float(np.abs(ref.feet_pos[stance, :, 2] - ref.sole_height).max()),
        flight_min_foot_clearance=float((ref.feet_pos[~stance, :, 2] - ref.sole_height).min()),
        joint_limit_margin=float(np.minimum(joints - lower, upper - joints).min()),
        max_velocity_ratio=float((np.abs(ref.qvel[:, 6:]) / velocity).max()),
        max_torque_ratio=float((peak / effort).max()),
        peak_torque={n: float(v) for n, v in zip(names, peak, strict=True)},
        effort_limit={n: float(v) for n, v in zip(names, effort, strict=True)},
    )
