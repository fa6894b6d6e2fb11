# SPDX-License-Identifier: Apache-2.0
"""The concealed-effect *truth* simulator: injects effects through code independent of the hypothesis classes.

Nothing here calls :mod:`gmloco.deploy.mismatch.replay` or :mod:`gmloco.deploy.mismatch.terrain`:

* model edits are made on the ``MjSpec`` before compiling (armature, a payload body, link geometry, masses);
* actuator effects live in :class:`TruthActuator` (a FIFO command buffer at physics-step resolution, explicit
  smooth Coulomb and viscous friction, a DC-motor envelope, per-joint gain errors), the tool instead uses
  interpolated delays, MuJoCo ``frictionloss`` / ``dof_damping`` and a clipped PD law;
* sensor effects live in :class:`TruthSensor` (offsets, biases, a rotated IMU, noise, quantisation);
* terrain effects are an independent 3 x 3 sole grid per foot in :func:`truth_terrain_wrench`.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["TruthActuator", "TruthEffect", "TruthSensor", "truth_spec_edit", "truth_terrain_wrench"]


@dataclass
class TruthEffect:
    """One injected effect (benchmark vocabulary = tool vocabulary, plus out-of-library ids)."""

    id: str = "none"
    """Effect id (``none``, a library id, or ``ool.*`` for out-of-library effects)."""
    params: dict[str, list[float]] = field(default_factory=dict)
    """Parameter values in the tool's units (the truth key)."""


def _p(e: TruthEffect, eid: str, name: str, size: int = 1) -> np.ndarray:
    """Parameter of ``e`` if it is effect ``eid``, zeros otherwise."""
    if e.id != eid:
        return np.zeros(size)
    return np.asarray(e.params[name], float).reshape(size)


def truth_spec_edit(e: TruthEffect, rng: np.random.Generator, nuisance: bool) -> Any:
    """Return an ``MjSpec`` edit injecting model-level effects and nuisance mass/friction errors."""

    def edit(spec: Any) -> None:
        if nuisance:
            for b in spec.bodies:
                if b.name not in ("world", ""):
                    b.mass = b.mass * (1.0 + rng.uniform(-0.03, 0.03))
            for g in spec.geoms:
                if "_foot" in g.name:
                    g.friction[0] *= 1.0 + rng.uniform(-0.1, 0.1)
        if e.id == "joint.armature":
            for j in spec.joints:
                if j.name.endswith("_joint") and j.name != "floating_base_joint":
                    j.armature = j.armature * (1.0 + float(e.params["scale"][0]))
        if e.id == "body.mass_error":
            torso = spec.body("torso_link")
            pay = torso.add_body(name="payload", pos=[0.0, 0.0, 0.05])
            dm = float(e.params["delta_mass"][0])
            pay.mass = abs(dm) if dm > 0 else 1e-6
            pay.inertia = [1e-3 * max(dm, 1e-3)] * 3
            pay.explicitinertial = True
            if dm < 0:
                torso.mass = torso.mass + dm
        if e.id == "body.limb_mass":
            # a point mass at each link's centre of mass (thighs: hip-yaw links, shanks: knee links)
            links = ("left_hip_yaw_link", "right_hip_yaw_link", "left_knee_link", "right_knee_link")
            for name, dm in zip(links, e.params["delta_mass"], strict=True):
                b = spec.body(name)
                if dm > 0:
                    extra = b.add_body(name=f"{name}_extra", pos=list(b.ipos))
                    extra.mass, extra.inertia, extra.explicitinertial = float(dm), [1e-5] * 3, True
                elif dm < 0:
                    ratio = (b.mass + float(dm)) / b.mass
                    b.mass, b.inertia = b.mass * ratio, [v * ratio for v in b.inertia]
        if e.id == "ool.shank_length":
            for side in ("left", "right"):
                b = spec.body(f"{side}_ankle_pitch_link")
                b.pos = [b.pos[0], b.pos[1], b.pos[2] - float(e.params["dl"][0])]

    return edit


class TruthActuator:
    """Motor driver of the truth robot: PD on the *encoder* reading with its own non-idealities."""

    def __init__(self, e: TruthEffect, effort: np.ndarray, dt: float, rng: np.random.Generator, nuisance: bool) -> None:
        """Set up the delay FIFO and per-joint errors."""
        self.dt = dt
        steps = round(float(_p(e, "actuator.delay", "delay")[0]) / dt)
        self.fifo: deque = deque(maxlen=steps + 1)
        self.gain = (1.0 + float(_p(e, "actuator.gain_scale", "kp_scale")[0])) * (
            1.0 + (rng.uniform(-0.03, 0.03, 29) if nuisance else 0.0)
        )
        w = effort / 88.0
        self.tau_c = float(_p(e, "joint.coulomb_friction", "tau_c")[0]) * w
        self.b = float(_p(e, "joint.viscous_damping", "b")[0]) * w
        self.tau_c[:12] += _p(e, "joint.coulomb_friction_leg", "tau_c", 12)
        self.b[:12] += _p(e, "joint.viscous_damping_leg", "b", 12)
        self.droop = float(_p(e, "actuator.torque_speed", "droop")[0])
        self.effort = effort * (1.0 - float(_p(e, "actuator.torque_limit", "limit_loss")[0]))
        half = 0.5 * _p(e, "actuator.backlash", "width", 3)
        # hip pitch/roll/yaw, knee, ankle pitch/roll per leg -> groups hip, knee, ankle
        self.backlash_half = np.zeros(29)
        self.backlash_half[:12] = np.tile(half[[0, 0, 0, 1, 2, 2]], 2)
        self.lag = float(e.params["tau_lag"][0]) if e.id == "ool.current_lag" else 0.0
        self.tau_prev = np.zeros(29)

    def motor_torque(self, cmd: tuple, q_enc: np.ndarray, dq_enc: np.ndarray) -> np.ndarray:
        """Torque the motor produces this physics step (what tau_est reports) [N*m], shape [29]."""
        self.fifo.append(cmd)
        q_t, dq_t, kp, kd, tff = self.fifo[0]
        e = q_t - q_enc
        e = np.sign(e) * np.maximum(np.abs(e) - self.backlash_half, 0.0)  # dead band of the position loop
        tau = self.gain * (kp * e + kd * (dq_t - dq_enc)) + tff
        if self.lag > 0:  # first-order current loop (out of library)
            tau = self.tau_prev + (tau - self.tau_prev) * min(1.0, self.dt / self.lag)
        env = self.effort * np.maximum(0.0, 1.0 - self.droop * np.abs(dq_enc))  # DC-motor envelope
        tau = np.minimum(np.maximum(tau, -env), env)
        self.tau_prev = tau
        return tau

    def joint_friction(self, dq: np.ndarray) -> np.ndarray:
        """Friction torque at the joint (smooth Coulomb + viscous) [N*m], shape [29]."""
        return -self.tau_c * np.tanh(dq / 0.04) - self.b * dq


@dataclass
class NoiseCfg:
    """Sensor noise of the truth robot (roughly G1-like)."""

    q: float = 2e-4
    """Encoder noise std [rad]."""
    dq: float = 0.015
    """Joint velocity noise std [rad/s]."""
    tau: float = 0.15
    """tau_est noise std [N*m]."""
    gyro: float = 0.004
    """Gyro noise std [rad/s]."""
    acc: float = 0.04
    """Accelerometer noise std [m/s^2]."""
    quat: float = 0.001
    """Orientation noise std [rad]."""


class TruthSensor:
    """Measurement chain of the truth robot."""

    def __init__(self, e: TruthEffect, rng: np.random.Generator, noise: NoiseCfg | None) -> None:
        """Set offsets, biases and mounting rotation."""
        self.rng, self.noise = rng, noise
        self.offset = np.zeros(29)
        self.offset[:12] = _p(e, "sensor.encoder_offset", "offset", 12)
        self.gyro_bias = _p(e, "imu.gyro_bias", "bias", 3)
        r, p = _p(e, "imu.misalignment", "angle", 2)
        cr, sr, cp, sp = np.cos(r), np.sin(r), np.cos(p), np.sin(p)
        self.R = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
        self.qm = np.array([np.cos(r / 2), np.sin(r / 2), 0, 0]), np.array([np.cos(p / 2), 0, np.sin(p / 2), 0])

    def _n(self, std: float, size: int) -> np.ndarray:
        """Gaussian noise (zero when noise is off)."""
        return self.rng.normal(0.0, std, size) if self.noise is not None else np.zeros(size)

    def encoders(self, q: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Measured joint position and velocity."""
        n = self.noise
        return q + self.offset + self._n(n.q if n else 0, 29), dq + self._n(n.dq if n else 0, 29)

    def imu(self, quat: np.ndarray, gyro: np.ndarray, acc: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Measured IMU quaternion, gyro and accelerometer from pelvis-frame truth."""
        n = self.noise
        qx, qy = self.qm
        qq = _qmul(_qmul(quat, qx), qy)
        if n is not None:
            dv = self._n(n.quat, 3) / 2
            qq = _qmul(qq, np.array([1.0, *dv]))
            qq /= np.linalg.norm(qq)
        g = self.R.T @ gyro + self.gyro_bias + self._n(n.gyro if n else 0, 3)
        a = self.R.T @ acc + self._n(n.acc if n else 0, 3)
        return qq, g, a

    def tau(self, tau: np.ndarray) -> np.ndarray:
        """Measured tau_est."""
        return tau + self._n(self.noise.tau if self.noise else 0, 29)


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of two quaternions (w, x, y, z)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ]
    )


_GX, _GY = np.meshgrid(np.linspace(-0.05, 0.125, 3), np.linspace(-0.025, 0.025, 3))
_GRID = np.stack([_GX.ravel(), _GY.ravel(), np.full(9, -0.035)], axis=1)  # 3 x 3 sole grid, ankle-roll frame [m]


def truth_terrain_wrench(e: TruthEffect, model: Any, data: Any, feet: list[int]) -> None:
    """Add the injected terrain law (if any) to ``data.xfrc_applied`` of the feet (independent 3 x 3 grid)."""
    if not e.id.startswith("terrain."):
        return
    area = 0.175 * 0.05 / 9.0
    alpha = 8.0e6
    val = float(next(iter(e.params.values()))[0])
    for b in feet:
        rot = data.xmat[b].reshape(3, 3)
        arm_b = _GRID @ rot.T
        pts = data.xpos[b] + arm_b
        depth = np.clip(-pts[:, 2], 0.0, None)
        # point velocity = v_origin + w x r, from the body's 6D velocity (MuJoCo cvel is COM-based; use mj_objectVelocity)
        import mujoco

        v6 = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, b, v6, 0)
        vz = v6[5] + np.cross(v6[:3], arm_b)[:, 2]
        if e.id == "terrain.stiffness_scale":
            f = val * alpha * area * depth
        elif e.id == "terrain.depth_hardening":
            f = val * alpha * area * depth**2
        elif e.id == "terrain.rate_drag":
            f = val * area * np.square(np.minimum(vz, 0.0)) * (depth > 0)
        else:  # terrain.cohesion
            f = -val * area * np.tanh(depth / 0.001)
        r = pts - data.xipos[b]
        force = np.array([0.0, 0.0, f.sum()])
        torque = np.cross(r, np.stack([np.zeros(9), np.zeros(9), f], 1)).sum(0)
        data.xfrc_applied[b, :3] += force
        data.xfrc_applied[b, 3:] += torque
