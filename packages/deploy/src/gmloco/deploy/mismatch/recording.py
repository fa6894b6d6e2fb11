# SPDX-License-Identifier: Apache-2.0
"""In-memory G1 recording on a uniform time grid: what the mismatch tool analyses.

A :class:`Recording` holds only what a real G1 logs (``unitree_hg`` LowState / LowCmd fields) plus the
optional base odometry. It is built from an MCAP log by :mod:`gmloco.deploy.mismatch.io` (through the
logs package's reader) or directly from arrays (tests, benchmark generator).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from gmloco.deploy.logs.g1 import G1_JOINT_NAMES

__all__ = ["SUPPORTS", "Recording", "Support", "support_from_label"]

Support = Literal["free", "gantry", "fixed"]
"""How the pelvis is held: ``free`` (a floating base on its own feet), ``gantry`` (hanging from a rigid gantry)
or ``fixed`` (bolted to a stand). Gantry and fixed are the same to the replay: the pelvis does not move."""

SUPPORTS: tuple[str, ...] = ("free", "gantry", "fixed")
"""Every :data:`Support` value."""


def support_from_label(label: str) -> Support:
    """Map the run metadata's ``support`` label (``packages/deploy/SCHEMA.md``) to a :data:`Support`.

    ``none`` (or empty) is a free base; the simulator's ``virtual_gantry(...)`` is a roll/pitch spring on a robot
    that stands on its own feet, so it is a free base too.

    Raises:
        ValueError: an unknown label (a typo must not silently become a free base).
    """
    s = label.strip().lower()
    if s in ("", "none", "free"):
        return "free"
    if s in ("gantry", "fixed"):
        return "gantry" if s == "gantry" else "fixed"
    if s.startswith("virtual_gantry("):
        return "free"
    raise ValueError(
        f"run metadata support={label!r} is not one of none, free, gantry, fixed or virtual_gantry(...): say how "
        "the pelvis was held (gantry or fixed: pelvis does not move; none: the robot stands on its own feet), or "
        "override it with gmloco-mismatch --support"
    )


@dataclass
class Recording:
    """A G1 run resampled on a uniform grid. Per-joint arrays are in :attr:`joint_names` order."""

    t: np.ndarray
    """Sample times [s], shape [N], uniform spacing."""
    q: np.ndarray
    """Measured joint positions (LowState ``motor_state.q``) [rad], shape [N, 29]."""
    dq: np.ndarray
    """Measured joint velocities (``motor_state.dq``) [rad/s], shape [N, 29]."""
    tau_est: np.ndarray
    """Estimated joint torques (``motor_state.tau_est``) [N*m], shape [N, 29]."""
    q_cmd: np.ndarray
    """Commanded positions (LowCmd ``motor_cmd.q``) [rad], shape [N, 29]."""
    dq_cmd: np.ndarray
    """Commanded velocities (``motor_cmd.dq``) [rad/s], shape [N, 29]."""
    kp: np.ndarray
    """Position gains (``motor_cmd.kp``) [N*m/rad], shape [N, 29]."""
    kd: np.ndarray
    """Velocity gains (``motor_cmd.kd``) [N*m*s/rad], shape [N, 29]."""
    tau_ff: np.ndarray
    """Feed-forward torques (``motor_cmd.tau``) [N*m], shape [N, 29]."""
    imu_quat: np.ndarray
    """IMU orientation (w, x, y, z) in world (``imu_state.quaternion``), shape [N, 4]."""
    imu_gyro: np.ndarray
    """IMU angular velocity in the IMU frame [rad/s], shape [N, 3]."""
    imu_acc: np.ndarray
    """IMU specific force in the IMU frame [m/s^2] (+9.81 on z at rest), shape [N, 3]."""
    base_pos: np.ndarray | None = None
    """Optional pelvis position in the odometry frame [m], shape [N, 3]."""
    base_quat: np.ndarray | None = None
    """Optional pelvis orientation (w, x, y, z), shape [N, 4]."""
    base_linvel: np.ndarray | None = None
    """Optional pelvis linear velocity in the pelvis frame [m/s], shape [N, 3]."""
    base_angvel: np.ndarray | None = None
    """Optional pelvis angular velocity in the pelvis frame [rad/s], shape [N, 3]."""
    valid: np.ndarray | None = None
    """Per-sample flag, False inside gaps filled by resampling, shape [N]; all True when ``None``."""
    joint_names: tuple[str, ...] = G1_JOINT_NAMES
    """Joint order of every per-joint array."""
    meta: dict[str, str] = field(default_factory=dict)
    """Free-form metadata (source file, controller, material)."""
    support: Support = "free"
    """How the pelvis is held (run metadata ``support``); the replay welds a gantry or fixed pelvis in place."""

    @property
    def fixed_base(self) -> bool:
        """Whether the pelvis is held in place (``support`` is ``gantry`` or ``fixed``)."""
        return self.support != "free"

    @property
    def n(self) -> int:
        """Number of samples."""
        return len(self.t)

    @property
    def dt(self) -> float:
        """Sample period [s]."""
        return float(np.median(np.diff(self.t))) if self.n > 1 else 0.0

    @property
    def has_odometry(self) -> bool:
        """Whether base pose and velocity are logged."""
        return all(x is not None for x in (self.base_pos, self.base_quat, self.base_linvel, self.base_angvel))

    def odometry(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """Return ``(base_pos, base_quat, base_linvel, base_angvel)`` when all are logged, else ``None``."""
        if self.base_pos is None or self.base_quat is None or self.base_linvel is None or self.base_angvel is None:
            return None
        return self.base_pos, self.base_quat, self.base_linvel, self.base_angvel

    @property
    def acc_derived(self) -> bool:
        """Whether the accelerometer is derived, not measured (``meta["derived_signals"]`` names it).

        A finite difference of the logged velocity cannot be compared with a simulated sensor sample.
        """
        return "imu.accelerometer" in str(self.meta.get("derived_signals", "")).split(",")

    def valid_mask(self) -> np.ndarray:
        """Return the per-sample validity mask, shape [N]."""
        return np.ones(self.n, bool) if self.valid is None else self.valid.astype(bool)

    def slice(self, start: int, stop: int) -> Recording:
        """Return samples ``start:stop`` as a new recording (arrays are views)."""
        kw = {}
        for name in _ARRAYS:
            a = getattr(self, name)
            kw[name] = None if a is None else a[start:stop]
        return replace(self, **kw)


_ARRAYS = (
    "t",
    "q",
    "dq",
    "tau_est",
    "q_cmd",
    "dq_cmd",
    "kp",
    "kd",
    "tau_ff",
    "imu_quat",
    "imu_gyro",
    "imu_acc",
    "base_pos",
    "base_quat",
    "base_linvel",
    "base_angvel",
    "valid",
)
