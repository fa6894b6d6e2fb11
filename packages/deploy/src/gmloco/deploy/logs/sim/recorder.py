# SPDX-License-Identifier: Apache-2.0
"""Record a MuJoCo C G1 simulation in the log schema (the simulator side of ``G1LogWriter``).

Call order per physics step, so that every logged quantity refers to the same state x_k::

    mujoco.mj_step1(model, data)        # kinematics, contacts, position/velocity sensors of x_k
    ... compute and set qfrc_applied ...
    snap = recorder.snapshot(data)      # q, dq, base state of x_k
    mujoco.mj_step2(model, data)        # qacc, accelerometer, contact forces of x_k; integrate to x_{k+1}
    recorder.record(t_k, snap, data, tau_k)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gmloco.deploy.logs.rotations import quat_rotate_inv, quat_to_rpy
from gmloco.deploy.logs.sim.ground import GroundContact
from gmloco.deploy.logs.writer import G1LogWriter

__all__ = ["MujocoG1Recorder", "StateSnapshot"]


@dataclass
class StateSnapshot:
    """State x_k copied between ``mj_step1`` and ``mj_step2``."""

    q: np.ndarray
    """Joint positions [rad], [29]."""
    dq: np.ndarray
    """Joint velocities [rad/s], [29]."""
    base_pos: np.ndarray
    """Pelvis position in world [m], [3]."""
    base_quat: np.ndarray
    """Pelvis orientation (w, x, y, z), [4]."""
    base_lin_vel_world: np.ndarray
    """Pelvis linear velocity in world [m/s], [3]."""
    base_ang_vel_body: np.ndarray
    """Pelvis angular velocity in the pelvis frame [rad/s], [3]."""
    gyro: np.ndarray
    """IMU gyroscope [rad/s], [3]."""


class MujocoG1Recorder:
    """Writes LowState, LowCmd, odometry and privileged contact truth from ``mujoco.MjData``."""

    def __init__(self, writer: G1LogWriter, model: Any, ground: GroundContact | None = None) -> None:
        """Resolve the IMU sensors (``imu_ang_vel``, ``imu_lin_acc`` on site ``imu_in_pelvis`` in the mjlab MJCF)."""
        self.writer, self.model, self.ground = writer, model, ground
        self._gyro = self._sensor_slice("imu_ang_vel")
        self._acc = self._sensor_slice("imu_lin_acc")

    def _sensor_slice(self, name: str) -> slice:
        """Return the sensordata slice of a named sensor."""
        s = self.model.sensor(name)
        return slice(int(s.adr[0]), int(s.adr[0] + s.dim[0]))

    def snapshot(self, data: Any) -> StateSnapshot:
        """Copy the state x_k (call after ``mj_step1``)."""
        return StateSnapshot(
            q=data.qpos[7:].copy(),
            dq=data.qvel[6:].copy(),
            base_pos=data.qpos[0:3].copy(),
            base_quat=data.qpos[3:7].copy(),
            base_lin_vel_world=data.qvel[0:3].copy(),
            base_ang_vel_body=data.qvel[3:6].copy(),
            gyro=data.sensordata[self._gyro].copy(),
        )

    def record_lowstate(self, t: float, snap: StateSnapshot, data: Any, tau: np.ndarray) -> None:
        """Write LowState of x_k (call after ``mj_step2``); ``tau`` [N*m] is the applied joint torque."""
        self.writer.write_lowstate(
            t,
            snap.q,
            snap.dq,
            tau,
            snap.base_quat,  # imu_in_pelvis has identity orientation w.r.t. the pelvis
            snap.gyro,
            data.sensordata[self._acc],
            ddq=data.qacc[6:],
            rpy=quat_to_rpy(snap.base_quat),
            tick=round(t * 1000),  # LowState tick counts milliseconds
        )

    def record_odometry(self, t: float, snap: StateSnapshot) -> None:
        """Write ground-truth base odometry (velocities in the pelvis frame)."""
        v_body = quat_rotate_inv(snap.base_quat, snap.base_lin_vel_world)
        self.writer.write_odometry(t, snap.base_pos, snap.base_quat, v_body, snap.base_ang_vel_body)

    def record_contact(self, t: float, data: Any) -> None:
        """Write privileged foot contact truth from the ground model (call after ``mj_step2``)."""
        if self.ground is not None:
            self.writer.write_sim_contact(t, *self.ground.foot_state(self.model, data))
