# SPDX-License-Identifier: Apache-2.0
"""One MPM episode as an MCAP recording in the project's log schema (``gmloco.deploy.logs``), at the policy rate.

Written from the scene's 50 Hz log of one robot: ``/lowstate/joint_states`` + ``/lowstate/imu`` (joints in the
G1 SDK order; torque = the PD law's; IMU = pelvis orientation, body-frame angular velocity and specific force from
the finite-differenced pelvis velocity), ``/lowcmd`` (targets and gains), ``/command/velocity``, ``/odometry``,
``/policy/action`` and ``/sim/foot_contact`` (sand force on each sole, contact = vertical force > 40 N as in
GM-Loco, sinkage below the local surface). ``gmloco-logs`` and the mismatch analysis read these files.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.logs import G1_JOINT_NAMES, G1LogWriter, LogWriterCfg, RunMetadata
from gmloco.deploy.logs.schema import (
    TOPIC_COMMAND,
    TOPIC_ETA,
    TOPIC_IMU,
    TOPIC_JOINT_STATES,
    TOPIC_LOWCMD,
    TOPIC_ODOMETRY,
    TOPIC_POLICY_ACTION,
    TOPIC_SIM_CONTACT,
    TOPIC_TF,
)

__all__ = ["CONTACT_FORCE_N", "write_episode_mcap"]

CONTACT_FORCE_N = 40.0
"""Vertical sand force above which a foot counts as in contact [N] (GM-Loco's threshold)."""


def _quat_rotate_inv(q_xyzw: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors [T, 3] by the inverse of quaternions (x, y, z, w) [T, 4]."""
    u, w = -q_xyzw[:, :3], q_xyzw[:, 3:4]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def write_episode_mcap(path: str | Path, ep: dict[str, Any], meta: dict[str, str]) -> Path:
    """Write one robot's episode log to ``path`` (overwritten); return the path.

    Args:
        path: Output ``.mcap`` file.
        ep: Per-step arrays of one robot at the policy rate: ``dt`` [s], ``base_q`` [T, 7] (p, q_xyzw),
            ``base_qd`` [T, 6] (world linear, angular), ``joint_q`` / ``joint_qd`` / ``target`` / ``action``
            [T, A], ``foot_force`` [T, 2, 3] [N], ``foot_sinkage`` [T, 2] [m], ``command`` [3], ``joint_names`` [A],
            ``kp`` / ``kd`` [A]; optionally ``eta`` [T], the student's decoded stiffness [-] (``/student/eta``,
            written where finite: other policies decode none).
        meta: ``policy``, ``material`` and free-form notes for the run metadata.
    """
    dt, q = float(ep["dt"]), np.asarray(ep["base_q"], dtype=np.float64)
    order = [list(ep["joint_names"]).index(n) for n in G1_JOINT_NAMES]
    jq, jqd, tgt = (np.asarray(ep[k], dtype=np.float64)[:, order] for k in ("joint_q", "joint_qd", "target"))
    kp, kd = np.asarray(ep["kp"])[order], np.asarray(ep["kd"])[order]
    quat_wxyz = np.concatenate([q[:, 6:7], q[:, 3:6]], axis=1)
    v_world, w_world = np.asarray(ep["base_qd"])[:, :3], np.asarray(ep["base_qd"])[:, 3:6]
    gyro = _quat_rotate_inv(q[:, 3:7], w_world)
    v_body = _quat_rotate_inv(q[:, 3:7], v_world)
    # specific force f = R^T (a - g), g = (0, 0, -9.81): reads +9.81 on z at rest
    acc_world = np.gradient(v_world, dt, axis=0) if len(q) > 1 else np.zeros_like(v_world)
    acc = _quat_rotate_inv(q[:, 3:7], acc_world + np.array([0.0, 0.0, 9.81]))
    force = np.asarray(ep["foot_force"], dtype=np.float64)
    sink = np.asarray(ep["foot_sinkage"], dtype=np.float64)
    topics = (TOPIC_JOINT_STATES, TOPIC_IMU, TOPIC_LOWCMD, TOPIC_COMMAND, TOPIC_ODOMETRY, TOPIC_TF,
              TOPIC_POLICY_ACTION, TOPIC_SIM_CONTACT)  # fmt: skip
    md = RunMetadata(controller="policy", policy=meta.get("policy", "none"), material=meta.get("material", "sand"),
                     contact_model="mpm", source="sim", lowstate_rate_hz=1.0 / dt, control_rate_hz=1.0 / dt,
                     notes=meta.get("notes", ""),
                     # the accelerometer below is a central difference of the logged base velocity, not a sensor
                     extra={"derived_signals": "imu.accelerometer"})  # fmt: skip
    cmd = np.asarray(ep["command"], dtype=np.float64)
    zeros = np.zeros(len(G1_JOINT_NAMES))
    eta = np.asarray(ep.get("eta", np.full(len(q), np.nan)), dtype=np.float64).reshape(-1)[: len(q)]
    has_eta = bool(np.isfinite(eta).any())
    with G1LogWriter(path, md, LogWriterCfg(topics=topics, overwrite=True)) as w:
        if has_eta:  # declared with its names and units (the log analysis' eta panel reads them)
            w.declare(TOPIC_ETA, names=["eta"], units=["1"])
        for t in range(len(q)):
            ts = t * dt
            tau = kp * (tgt[t] - jq[t]) - kd * jqd[t]
            w.write_lowstate(ts, jq[t], jqd[t], tau, quat_wxyz[t], gyro[t], acc[t])
            w.write_lowcmd(ts, tgt[t], zeros, kp, kd, zeros)
            w.write_command(ts, cmd[0], cmd[1], cmd[2])
            w.write_odometry(ts, q[t, :3], quat_wxyz[t], v_body[t], gyro[t])
            w.write_policy(ts, action=np.asarray(ep["action"][t], dtype=np.float64))
            w.write_sim_contact(ts, force[t, :, 2] > CONTACT_FORCE_N, force[t], sink[t])
            if has_eta and t < len(eta) and np.isfinite(eta[t]):
                w.write_eta(ts, eta[t : t + 1])
        w.close(meta.get("end_reason", "completed"))
    return Path(path)
