# SPDX-License-Identifier: Apache-2.0
"""Whole-body inverse kinematics of the G1 on its MuJoCo model (mujoco's Python API, CPU).

Each frame runs Gauss-Newton steps over the free base and the 29 joints. The whole-body CoM, both sole sites
(position and orientation, soles flat) and, when asked, the angular momentum about the CoM over the step from
the previous frame are primary tasks, solved by a damped pseudo-inverse (weighted with the momentum task, so
that waist and arm motion cost more than base and leg motion); the pelvis orientation is primary without the
momentum task and a null-space task or absent with it; a posture step toward the standing pose (waist and
arms) acts in the remaining null space. Frames are solved in order, each warm-started from the previous one, so
the joint trajectory is as smooth as the task trajectory.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from gmloco.deploy.g1 import G1_FOOT_SITES

__all__ = [
    "G1_STANDING_JOINT_POS",
    "IkCfg",
    "IkTargets",
    "WholeBodyIk",
    "g1_joint_limits",
    "load_g1_model",
    "standing_qpos",
]

G1_STANDING_JOINT_POS = {
    r"hip_pitch": -0.1,
    r"knee": 0.3,
    r"ankle_pitch": -0.2,
    r"shoulder_pitch": 0.2,
    r"elbow": 1.28,
}
"""Standing pose of mjlab's G1 ``HOME_KEYFRAME`` (both sides) [rad]; shoulder roll is +-0.2 rad by side."""
_SHOULDER_ROLL = 0.2
"""|shoulder roll| of the standing pose [rad], positive on the left."""


def _g1_actuator_table() -> list[tuple[object, float]]:
    """Return mjlab's G1 actuator groups with the motor velocity limit of each [rad/s] (``g1_constants``).

    Waist pitch / roll and the ankles are driven by two 5020 motors through a linkage that mjlab models as 1:1
    (twice the effort, the 5020's velocity limit).
    """
    from mjlab.asset_zoo.robots.unitree_g1 import g1_constants as g1

    return [
        (g1.G1_ACTUATOR_5020, g1.ACTUATOR_5020.velocity_limit),
        (g1.G1_ACTUATOR_7520_14, g1.ACTUATOR_7520_14.velocity_limit),
        (g1.G1_ACTUATOR_7520_22, g1.ACTUATOR_7520_22.velocity_limit),
        (g1.G1_ACTUATOR_4010, g1.ACTUATOR_4010.velocity_limit),
        (g1.G1_ACTUATOR_WAIST, g1.ACTUATOR_5020.velocity_limit),
        (g1.G1_ACTUATOR_ANKLE, g1.ACTUATOR_5020.velocity_limit),
    ]


def load_g1_model() -> mujoco.MjModel:
    """Return mjlab's G1 MJCF with the actuator armature of mjlab's G1 config (no ground, no actuators)."""
    from mjlab.asset_zoo.robots.unitree_g1 import g1_constants as g1

    model = mujoco.MjModel.from_xml_path(str(g1.G1_XML))
    for act, _ in _g1_actuator_table():
        for j in _match_joints(model, act.target_names_expr):  # type: ignore[attr-defined]
            model.dof_armature[model.jnt_dofadr[j]] = act.armature  # type: ignore[attr-defined]
    return model


def g1_joint_limits(model: mujoco.MjModel) -> tuple[np.ndarray, np.ndarray]:
    """Effort limit [N m] and velocity limit [rad/s] of every hinge joint, in ``qpos[7:]`` order, shape [29] each."""
    effort, velocity = np.full(model.njnt - 1, np.nan), np.full(model.njnt - 1, np.nan)
    for act, vel in _g1_actuator_table():
        for j in _match_joints(model, act.target_names_expr):  # type: ignore[attr-defined]
            effort[j - 1], velocity[j - 1] = act.effort_limit, vel  # type: ignore[attr-defined]
    if np.isnan(effort).any():
        missing = [model.joint(j + 1).name for j in np.flatnonzero(np.isnan(effort))]
        raise ValueError(f"no mjlab G1 actuator drives joints {missing}")
    return effort, velocity


def _match_joints(model: mujoco.MjModel, patterns: tuple[str, ...] | list[str]) -> list[int]:
    """Ids of the hinge joints whose full name matches one of the regular expressions."""
    import re

    return [
        j
        for j in range(model.njnt)
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE
        and any(re.fullmatch(p, model.joint(j).name) for p in patterns)
    ]


def standing_qpos(model: mujoco.MjModel) -> np.ndarray:
    """Standing configuration (mjlab HOME pose) with the base at the origin, shape [nq]."""
    q = np.zeros(model.nq)
    q[3] = 1.0
    for j in range(1, model.njnt):
        name = model.joint(j).name
        value = next((v for k, v in G1_STANDING_JOINT_POS.items() if name.endswith(f"{k}_joint")), 0.0)
        if name.endswith("shoulder_roll_joint"):
            value = _SHOULDER_ROLL if name.startswith("left") else -_SHOULDER_ROLL
        q[model.jnt_qposadr[j]] = value
    return q


@dataclass
class IkCfg:
    """Gains and stopping rule of the whole-body IK (tasks first, posture in their null space)."""

    posture_gain_waist: float = 0.2
    """Fraction of the waist posture error removed per iteration, inside the task null space [-]."""
    posture_gain_arms: float = 0.2
    """Same for the arm joints [-]."""
    posture_gain_legs: float = 0.0
    """Same for the leg joints (the CoM, sole and pelvis tasks already fix the legs) [-]."""
    damping: float = 1e-10
    """Damping of the task pseudo-inverse [m^2]."""
    min_iterations: int = 3
    """Gauss-Newton iterations per frame at least (the posture term keeps converging after the tasks)."""
    max_iterations: int = 100
    """Gauss-Newton iterations per frame at most."""
    tolerance: float = 1e-9
    """Stop when the largest CoM / sole position error is below this [m]."""
    limit_margin: float = 0.02
    """Joint positions are kept this far inside the joint range [rad]."""
    weight_waist: float = 1.0
    """Cost of waist motion relative to the base and leg motion in the weighted pseudo-inverse of the momentum
    tasks [-]; above 1, the momentum is balanced by turning the whole trunk on the hips rather than the waist."""
    weight_arms: float = 1.0
    """Same for the arm joints [-]."""


@dataclass
class IkTargets:
    """Targets of one frame, in the world frame."""

    com: np.ndarray
    """Whole-body CoM [m], shape [3]."""
    feet: np.ndarray
    """Sole-site positions, left then right [m], shape [2, 3]."""
    pelvis_pitch: float | None
    """Pelvis pitch about the world y axis [rad] (roll and yaw are zero); a null-space target when ``angmom`` is
    set; None: no pelvis task (``angmom`` must then be set), the pelvis turns as the momentum task requires."""
    angmom: np.ndarray | None = None
    """Whole-body angular momentum about the CoM to hold over the step from the previous frame [kg m^2/s],
    shape [3]; None: no momentum task, the pelvis orientation is a primary task instead."""
    dt: float = 0.01
    """Time since the previous frame [s] (momentum task only)."""
    waist_pitch: float = 0.0
    """Posture target of the waist pitch joint [rad] (the standing pose's is 0)."""


class WholeBodyIk:
    """Frame-by-frame IK of the G1 toward :class:`IkTargets`.

    Args:
        model: G1 model from :func:`load_g1_model`.
        cfg: Weights and stopping rule.
    """

    def __init__(self, model: mujoco.MjModel, cfg: IkCfg) -> None:
        self.model, self.cfg = model, cfg
        self.data = mujoco.MjData(model)
        self.feet = [model.site(n).id for n in G1_FOOT_SITES]
        self.pelvis = model.body("pelvis").id
        self.q_nominal = standing_qpos(model)
        self.q = self.q_nominal.copy()
        hinge = range(1, model.njnt)
        self.lower = np.array([model.jnt_range[j, 0] for j in hinge]) + cfg.limit_margin
        self.upper = np.array([model.jnt_range[j, 1] for j in hinge]) - cfg.limit_margin
        self.posture_gain = np.full(model.nv - 6, cfg.posture_gain_legs)
        weight = np.ones(model.nv)
        for j in hinge:
            name, dof = model.joint(j).name, model.jnt_dofadr[j]
            if name.startswith("waist"):
                self.posture_gain[dof - 6], weight[dof] = cfg.posture_gain_waist, cfg.weight_waist
            elif not any(k in name for k in ("hip", "knee", "ankle")):
                self.posture_gain[dof - 6], weight[dof] = cfg.posture_gain_arms, cfg.weight_arms
        self.inv_weight = 1.0 / weight
        """Inverse joint-space weight of the momentum tasks' pseudo-inverse, shape [nv]."""
        self.waist_pitch = model.jnt_qposadr[model.joint("waist_pitch_joint").id]
        """qpos index of the waist pitch joint."""
        self.mass = float(model.body_subtreemass[self.pelvis])
        self.foot_quat = np.zeros((2, 4))
        self.last_error = np.inf
        """Largest CoM / sole position error of the last solve [m]."""

    def set_state(self, q: np.ndarray) -> None:
        """Set the warm start and record the sole orientations of ``q`` as the foot orientation targets."""
        self.q = q.copy()
        self.data.qpos[:] = q
        mujoco.mj_kinematics(self.model, self.data)
        for i, s in enumerate(self.feet):
            mujoco.mju_mat2Quat(self.foot_quat[i], self.data.site_xmat[s])

    def momentum_matrix(self, q: np.ndarray) -> np.ndarray:
        """Centroidal angular momentum matrix ``A(q)``: angular momentum about the CoM = ``A q'``, shape [3, nv]."""
        m, d = self.model, self.data
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        out = np.zeros((3, m.nv))
        for k in range(m.nv):
            d.qvel[:] = 0.0
            d.qvel[k] = 1.0
            mujoco.mj_comVel(m, d)
            mujoco.mj_subtreeVel(m, d)
            out[:, k] = d.subtree_angmom[self.pelvis]
        d.qvel[:] = 0.0
        return out

    def _residuals(self, targets: IkTargets) -> tuple[list[np.ndarray], list[np.ndarray], float]:
        """(Jacobian, error) blocks of the CoM, sole and pelvis tasks at the current ``q``, largest position error."""
        m, d = self.model, self.data
        d.qpos[:] = self.q
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        jacs, errs = [], []
        jc = np.zeros((3, m.nv))
        mujoco.mj_jacSubtreeCom(m, d, jc, self.pelvis)
        e_com = targets.com - d.subtree_com[self.pelvis]
        jacs.append(jc)
        errs.append(e_com)
        worst = float(np.abs(e_com).max())
        for i, s in enumerate(self.feet):
            jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
            mujoco.mj_jacSite(m, d, jp, jr, s)
            e_pos = targets.feet[i] - d.site_xpos[s]
            jacs += [jp, jr]
            errs += [e_pos, _rot_error(self.foot_quat[i], d.site_xmat[s])]
            worst = max(worst, float(np.abs(e_pos).max()))
        if targets.pelvis_pitch is None:
            return jacs, errs, worst
        jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mujoco.mj_jacBody(m, d, jp, jr, self.pelvis)
        pelvis_quat = np.array([np.cos(targets.pelvis_pitch / 2), 0.0, np.sin(targets.pelvis_pitch / 2), 0.0])
        jacs.append(jr)
        errs.append(_rot_error(pelvis_quat, d.xmat[self.pelvis]))
        return jacs, errs, worst

    def midpoint(self, q_prev: np.ndarray, q: np.ndarray) -> np.ndarray:
        """Configuration halfway along the step from ``q_prev`` to ``q``, shape [nq]."""
        mid = q_prev.copy()
        step = np.zeros(self.model.nv)
        mujoco.mj_differentiatePos(self.model, step, 1.0, q_prev, q)
        mujoco.mj_integratePos(self.model, mid, step, 0.5)
        return mid

    def step_momentum(self, q_prev: np.ndarray, q: np.ndarray, dt: float) -> np.ndarray:
        """Angular momentum about the CoM of the step ``q_prev -> q`` over ``dt`` (midpoint rule) [kg m^2/s]."""
        step = np.zeros(self.model.nv)
        mujoco.mj_differentiatePos(self.model, step, dt, q_prev, q)
        return self.momentum_matrix(self.midpoint(q_prev, q)) @ step

    def _momentum_residual(self, targets: IkTargets, q_prev: np.ndarray, A: np.ndarray) -> np.ndarray:
        """Error of ``A (q - q_prev) / dt = angmom`` at the current ``q`` [kg m^2/s], shape [3]."""
        step = np.zeros(self.model.nv)
        mujoco.mj_differentiatePos(self.model, step, targets.dt, q_prev, self.q)
        assert targets.angmom is not None
        return targets.angmom - A @ step

    def solve(self, targets: IkTargets) -> np.ndarray:
        """Solve one frame from the current warm start; returns ``qpos`` [nq] and keeps it as the next start.

        Each iteration takes the damped pseudo-inverse step of the primary tasks (CoM, soles, and either the
        angular momentum or the pelvis orientation) and adds, in their null space, a step toward the pelvis
        orientation (when it is not primary) and the posture: ``dq = J+ e + (I - J+ J) dq_2``.
        """
        q_prev = self.q.copy()
        A = None
        for it in range(self.cfg.max_iterations):
            if targets.angmom is not None:
                # Midpoint rule: A at the middle of the step keeps the momentum of the discrete motion second-order.
                A = self.momentum_matrix(self.midpoint(q_prev, self.q))
            jacs, errs, worst = self._residuals(targets)
            if A is not None:
                e_mom = self._momentum_residual(targets, q_prev, A)
                worst = max(worst, float(np.abs(e_mom).max()) * targets.dt / self.mass)
            self.last_error = worst
            if worst < self.cfg.tolerance and it >= self.cfg.min_iterations:
                break
            dq_posture = np.zeros(self.model.nv)
            q_nominal = self.q_nominal.copy()
            q_nominal[self.waist_pitch] = targets.waist_pitch
            dq_posture[6:] = self.posture_gain * (q_nominal[7:] - self.q[7:])
            if A is None:
                J, e = np.concatenate(jacs), np.concatenate(errs)
                J_pinv = _pinv(J, self.cfg.damping)
                dq = J_pinv @ e + dq_posture - J_pinv @ (J @ dq_posture)
            else:
                J, e = np.concatenate([*jacs[:5], A / targets.dt]), np.concatenate([*errs[:5], e_mom])
                # Weighted minimum-norm step: waist and arm motion cost more than base and leg motion.
                # W^-1 J^T (J W^-1 J^T)^-1 = D (J D)^+ with D = W^-1/2.
                D = np.sqrt(self.inv_weight)
                J_pinv = D[:, None] * _pinv(J * D, self.cfg.damping)
                dq = J_pinv @ e
                # Pelvis orientation as a secondary task, the posture as a third, each in the null space above it.
                N = np.eye(self.model.nv) - J_pinv @ J
                if len(jacs) > 5:
                    JpN_pinv = _pinv(jacs[5] @ N, self.cfg.damping)
                    dq = dq + JpN_pinv @ (errs[5] - jacs[5] @ dq)
                    N = N - JpN_pinv @ (jacs[5] @ N)
                dq = dq + N @ dq_posture
            mujoco.mj_integratePos(self.model, self.q, dq, 1.0)
            self.q[7:] = np.clip(self.q[7:], self.lower, self.upper)
        return self.q.copy()


def _pinv(J: np.ndarray, damping: float) -> np.ndarray:
    """Damped right pseudo-inverse ``J^T (J J^T + damping I)^-1``."""
    return J.T @ np.linalg.inv(J @ J.T + damping * np.eye(J.shape[0]))


def _rot_error(target_quat: np.ndarray, xmat: np.ndarray) -> np.ndarray:
    """Rotation vector taking the current orientation (3x3 ``xmat``) to ``target_quat``, world frame [rad]."""
    current = np.zeros(4)
    mujoco.mju_mat2Quat(current, xmat)
    err = np.zeros(3)
    # mju_subQuat gives the rotation from b to a in the frame of b; rotate it into the world frame.
    mujoco.mju_subQuat(err, target_quat, current)
    return xmat.reshape(3, 3) @ err
