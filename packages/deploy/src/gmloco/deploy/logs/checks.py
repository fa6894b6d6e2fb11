# SPDX-License-Identifier: Apache-2.0
"""Soft contract checks on decoded logs: warn when magnitudes betray wrong units or conventions.

Declared units are enforced by the reader (``UnitsError``); these checks catch data that *claim* SI units
but are not (degrees logged as radians, accelerometer in g, (x, y, z, w) quaternions, dropped samples).
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np

from gmloco.deploy.g1 import G1_JOINT_NAMES
from gmloco.deploy.logs.errors import LogContractWarning
from gmloco.deploy.logs.schema import TOPIC_JOINT_STATES

if TYPE_CHECKING:
    from gmloco.deploy.logs.reader import G1Log

__all__ = ["check_contracts"]

_G = 9.81
_RANGE_MARGIN = 0.35  # [rad]; the 20 deg slack covers encoder offsets and sim joint-limit softness


def _warn(log: G1Log, msg: str) -> None:
    """Emit a contract warning prefixed with the file name."""
    warnings.warn(f"{log.path}: {msg}", LogContractWarning, stacklevel=4)


def _check_joint_ranges(log: G1Log) -> None:
    """Warn when joint positions leave the MJCF range (degrees logged as radians, wrong joint order)."""
    from gmloco.deploy.logs.analysis.kinematics import g1_model

    _, q = log.signal("lowstate.q")
    ranges = np.array([g1_model()["joint_ranges"][n] for n in G1_JOINT_NAMES])
    out = (q < ranges[:, 0] - _RANGE_MARGIN) | (q > ranges[:, 1] + _RANGE_MARGIN)
    frac = out.mean(axis=0)
    bad = [(G1_JOINT_NAMES[j], float(frac[j])) for j in np.flatnonzero(frac > 0.01)]
    if bad:
        _warn(
            log,
            f"joint positions outside the G1 joint ranges for {bad[:5]} (fraction of samples). "
            "Degrees logged as radians, or a wrong motor-index -> joint-name map?",
        )


def _check_imu(log: G1Log) -> None:
    """Warn on non-unit quaternions, (x, y, z, w) order, and accelerometers not in m/s^2."""
    _, quat = log.signal("imu.quaternion")
    norm = np.linalg.norm(quat, axis=1)
    if np.nanmax(np.abs(norm - 1.0)) > 1e-2:
        _warn(log, f"IMU quaternion norms range {np.nanmin(norm):.3f}..{np.nanmax(norm):.3f}, expected 1")
    if np.nanmedian(np.abs(quat[:, 0])) < 0.3 and np.nanmedian(np.abs(quat[:, 3])) > 0.9:
        _warn(
            log,
            "IMU quaternion looks like (x, y, z, w); the schema uses (w, x, y, z) as the Unitree IMU does",
        )
    _, acc = log.signal("imu.accelerometer")
    g = float(np.nanmedian(np.linalg.norm(acc, axis=1)))
    if not 0.5 * _G < g < 1.5 * _G:
        _warn(log, f"median accelerometer norm {g:.2f}, expected ~{_G} m/s^2 (logged in g, or gravity removed?)")


def _check_rate(log: G1Log) -> None:
    """Warn on gaps in the joint-state stream (dropped messages)."""
    t = log.channels[TOPIC_JOINT_STATES].time_ns * 1e-9
    if len(t) < 3:
        return
    dt = np.diff(t)
    med = float(np.median(dt))
    gaps = np.flatnonzero(dt > 3 * med)
    if gaps.size:
        _warn(
            log,
            f"{TOPIC_JOINT_STATES}: {gaps.size} gaps longer than 3x the median period {med * 1e3:.2f} ms "
            f"(first at t = {t[gaps[0]] - t[0]:.3f} s, {dt[gaps[0]] * 1e3:.1f} ms); dropped messages?",
        )


def check_contracts(log: G1Log) -> None:
    """Run all soft checks on a decoded log (warnings only)."""
    _check_joint_ranges(log)
    _check_imu(log)
    _check_rate(log)
