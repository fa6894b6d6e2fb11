# SPDX-License-Identifier: Apache-2.0
"""Make "real" recordings from the truth simulator: scripted motion, one hidden effect, noise and nuisances.

Only channels a real G1 logs are produced (LowState joints and IMU, LowCmd); base odometry only when asked
(as an estimator or mocap would provide). The truth key is returned separately so that callers write it where
the tool cannot read it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from gmloco.deploy.mismatch.benchmark.chirp import ChirpCfg, ChirpMotion
from gmloco.deploy.mismatch.benchmark.controller import MotionCfg, ScriptedMotion, default_gains
from gmloco.deploy.mismatch.benchmark.policy_motion import PolicyMotion, PolicyMotionCfg
from gmloco.deploy.mismatch.benchmark.truth import (
    NoiseCfg,
    TruthActuator,
    TruthEffect,
    TruthSensor,
    truth_spec_edit,
    truth_terrain_wrench,
)
from gmloco.deploy.mismatch.benchmark.truth_sand import TruthSand
from gmloco.deploy.mismatch.frames import quat_from_roll_pitch, quat_to_mat
from gmloco.deploy.mismatch.g1model import G1_EFFORT_LIMIT, G1SimCfg, build_model
from gmloco.deploy.mismatch.recording import Recording, Support

__all__ = ["EpisodeCfg", "generate"]


@dataclass
class EpisodeCfg:
    """One benchmark episode."""

    effect: TruthEffect = field(default_factory=TruthEffect)
    """Hidden effect (the truth key)."""
    motion: MotionCfg = field(default_factory=MotionCfg)
    """Scripted motion."""
    duration: float = 8.0
    """Recording length [s]."""
    rate_hz: float = 500.0
    """LowState / LowCmd rate [Hz]."""
    substeps: int = 4
    """Truth physics steps per log sample (explicit friction needs a short step)."""
    seed: int = 0
    """Noise and nuisance seed."""
    nuisance: bool = True
    """Draw small mass, friction and per-joint gain errors (never exactly nominal)."""
    noise: NoiseCfg | None = field(default_factory=NoiseCfg)
    """Sensor noise; ``None`` for noise-free recordings."""
    odometry: bool = False
    """Also log ground-truth base odometry."""
    drop_fraction: float = 0.0
    """Fraction of LowState samples dropped (marked invalid after resampling)."""
    keep_before_fall: float | None = None
    """If set and the truth robot falls, keep the log up to this many seconds before the fall instead of
    raising (as a user would trim a real log that ends in a fall); ``min_kept`` seconds must remain."""
    min_kept: float = 3.5
    """Shortest log kept after trimming a fall [s]."""
    ground: Literal["plane", "sand"] = "plane"
    """Truth ground: MuJoCo soft plane, or the project's 3D-RFT sand (float64 reference, :mod:`.truth_sand`)."""
    material: str = "dry_sand"
    """Sand medium (``gmloco.contact.MATERIAL_PRESETS``) when ``ground="sand"``."""
    policy: PolicyMotionCfg | None = None
    """If set, a trained walking policy drives the truth robot (with its own PD gains) instead of ``motion``."""
    support: Support = "free"
    """How the truth pelvis is held: ``free`` stands on the ground; ``gantry`` / ``fixed`` weld it in the air
    (tilted by up to 2 degrees per axis when ``nuisance`` is on), and the recording says so in its ``support``."""
    chirp: ChirpCfg | None = None
    """If set, joint chirps (:mod:`.chirp`) drive the truth robot instead of ``motion``; needs a held pelvis."""


def _initial_state(model: object, data: object, q0: np.ndarray) -> None:
    """Place the robot standing on the ground in the default pose."""
    import mujoco

    data.qpos[3:7] = [1, 0, 0, 0]
    data.qpos[7:] = q0
    data.qpos[2] = 0.8
    mujoco.mj_kinematics(model, data)
    feet = [model.body(f"{s}_ankle_roll_link").id for s in ("left", "right")]
    low = min(float((data.xpos[b] + np.array([0, 0, -0.035]) @ data.xmat[b].reshape(3, 3).T)[2]) for b in feet)
    data.qpos[2] -= low + 0.002


def _pelvis_imu(model: Any, data: Any, pelvis: int, fixed: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pelvis orientation, angular velocity and specific force (pelvis frame) of the truth robot.

    MuJoCo computes no sensor on a world-welded body, so a held pelvis gets those of a body at rest: no rotation,
    and minus gravity.
    """
    if fixed:
        quat = np.array(data.xquat[pelvis])
        return quat, np.zeros(3), quat_to_mat(quat).T @ -np.asarray(model.opt.gravity)
    return data.qpos[3:7].copy(), data.sensordata[0:3].copy(), data.sensordata[6:9].copy()


def generate(cfg: EpisodeCfg) -> tuple[Recording, dict]:
    """Simulate one episode; return the recording and its truth key."""
    import mujoco

    fixed = cfg.support != "free"
    if cfg.chirp is not None and not fixed:
        raise ValueError("EpisodeCfg.chirp needs support='gantry' or 'fixed': joint chirps are an in-air test")
    rng = np.random.default_rng(cfg.seed)
    dt_log = 1.0 / cfg.rate_hz
    dt = dt_log / cfg.substeps
    model = build_model(
        G1SimCfg(timestep=dt, ground=cfg.ground, fixed_base=fixed),
        spec_edit=truth_spec_edit(cfg.effect, rng, cfg.nuisance),
    )
    pelvis = model.body("pelvis").id
    if fixed and cfg.nuisance:
        model.body_quat[pelvis] = quat_from_roll_pitch(*rng.uniform(-0.035, 0.035, 2))
    jq, jv = slice(0 if fixed else 7, None), slice(0 if fixed else 6, None)
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    data = mujoco.MjData(model)
    act = TruthActuator(cfg.effect, G1_EFFORT_LIMIT, dt, rng, cfg.nuisance)
    sen = TruthSensor(cfg.effect, rng, cfg.noise)
    ctrl: ScriptedMotion | PolicyMotion | ChirpMotion
    if cfg.chirp is not None:
        ctrl = ChirpMotion(cfg.chirp)
        kp, kd = default_gains()
    elif cfg.policy is not None:
        ctrl = PolicyMotion(cfg.policy)
        kp, kd = ctrl.gains()
    else:
        ctrl = ScriptedMotion(cfg.motion)
        kp, kd = default_gains()
    if fixed:
        data.qpos[:] = ctrl.q0
    else:
        _initial_state(model, data, ctrl.q0)
    feet = [model.body(f"{s}_ankle_roll_link").id for s in ("left", "right")]
    sand = TruthSand(cfg.effect, cfg.material) if cfg.ground == "sand" else None
    n = round(cfg.duration * cfg.rate_hz)
    out = {
        k: np.zeros((n, w))
        for k, w in (
            ("q", 29),
            ("dq", 29),
            ("tau", 29),
            ("qc", 29),
            ("quat", 4),
            ("gyro", 3),
            ("acc", 3),
            ("pos", 3),
            ("bq", 4),
            ("v", 3),
            ("w", 3),
        )
    }
    tau = np.zeros(29)
    fell_at = None
    for k in range(n):
        mujoco.mj_forward(model, data)
        q_enc, dq_enc = sen.encoders(data.qpos[jq].copy(), data.qvel[jv].copy())
        quat, gyro, acc = sen.imu(*_pelvis_imu(model, data, pelvis, fixed))
        if isinstance(ctrl, PolicyMotion):
            qc = ctrl.targets(k * dt_log, quat, gyro, q_enc, dq_enc)
        else:
            qc = ctrl.targets(k * dt_log, quat, gyro)
        cmd = (qc, np.zeros(29), kp, kd, np.zeros(29))
        for sub in range(cfg.substeps):
            if sub:
                mujoco.mj_forward(model, data)
            qe = data.qpos[jq] + sen.offset
            tau = act.motor_torque(cmd, qe, data.qvel[jv])
            if sub == 0:
                tau_log = tau.copy()
            data.qfrc_applied[jv] = tau + act.joint_friction(data.qvel[jv])
            data.xfrc_applied[:] = 0.0
            if fixed:
                pass  # a held robot touches nothing
            elif sand is not None:
                sand.apply(model, data, feet)
            else:
                truth_terrain_wrench(cfg.effect, model, data, feet)
            mujoco.mj_step(model, data)
        out["q"][k], out["dq"][k], out["tau"][k], out["qc"][k] = q_enc, dq_enc, sen.tau(tau_log), qc
        out["quat"][k], out["gyro"][k], out["acc"][k] = quat, gyro, acc
        if fixed:  # a welded pelvis: pose of the body, at rest
            out["pos"][k], out["bq"][k] = data.xpos[pelvis], data.xquat[pelvis]
        else:
            rot = data.xmat[1].reshape(3, 3)
            out["pos"][k], out["bq"][k] = data.qpos[:3], data.qpos[3:7]
            out["v"][k], out["w"][k] = rot.T @ data.qvel[:3], data.qvel[3:6]
        if not fixed and data.qpos[2] < 0.45:
            msg = f"truth robot fell at t = {k * dt_log:.2f} s (effect {cfg.effect.id})"
            keep = None if cfg.keep_before_fall is None else round((k * dt_log - cfg.keep_before_fall) / dt_log)
            if keep is None or keep * dt_log < cfg.min_kept:
                raise RuntimeError(msg)
            fell_at, n = k * dt_log, keep
            out = {key: v[:n] for key, v in out.items()}
            break
    key = {"effect": cfg.effect.id, "params": cfg.effect.params, "seed": cfg.seed}
    if fell_at is not None:
        key["fell_at_s"], key["kept_s"] = fell_at, n * dt_log
    return _to_recording(cfg, out, n, dt_log, kp, kd, rng), key


def _to_recording(
    cfg: EpisodeCfg, o: dict, n: int, dt: float, kp: np.ndarray, kd: np.ndarray, rng: np.random.Generator
) -> Recording:
    """Pack arrays as a :class:`Recording` (with dropped samples marked invalid)."""
    valid = np.ones(n, bool)
    if cfg.drop_fraction > 0:
        valid[rng.random(n) < cfg.drop_fraction] = False
    odo = cfg.odometry
    return Recording(
        t=np.arange(n) * dt,
        q=o["q"],
        dq=o["dq"],
        tau_est=o["tau"],
        q_cmd=o["qc"],
        dq_cmd=np.zeros((n, 29)),
        kp=np.tile(kp, (n, 1)),
        kd=np.tile(kd, (n, 1)),
        tau_ff=np.zeros((n, 29)),
        imu_quat=o["quat"],
        imu_gyro=o["gyro"],
        imu_acc=o["acc"],
        base_pos=o["pos"] if odo else None,
        base_quat=o["bq"] if odo else None,
        base_linvel=o["v"] if odo else None,
        base_angvel=o["w"] if odo else None,
        valid=valid,
        meta={"controller": _controller_label(cfg), "source": "benchmark"},
        support=cfg.support,
    )


def _controller_label(cfg: EpisodeCfg) -> str:
    """Controller label of an episode (run metadata ``controller``)."""
    if cfg.chirp is not None:
        return "scripted_chirp"
    return "policy" if cfg.policy else f"scripted_{cfg.motion.kind}"
