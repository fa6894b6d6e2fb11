# SPDX-License-Identifier: Apache-2.0
"""MCAP <-> :class:`Recording`, through the logs package's reader and writer (no second MCAP reader here)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.mismatch.recording import Recording, support_from_label

__all__ = ["read_recording", "write_recording"]


def _resample(t_src: np.ndarray, x: np.ndarray, t: np.ndarray, hold: bool) -> np.ndarray:
    """Resample columns of ``x`` [M, ...] from ``t_src`` onto ``t`` (linear, or zero-order hold)."""
    flat = x.reshape(len(x), -1)
    if hold:
        # A message stamped at a grid time belongs to that sample: the grid (ts[0] + k / rate, float) and the
        # nanosecond stamps differ by round-off, and without the 1 us tolerance a held command lands one sample
        # late (a spurious 2 ms command delay at 500 Hz).
        idx = np.clip(np.searchsorted(t_src, t + 1e-6, side="right") - 1, 0, len(t_src) - 1)
        out = flat[idx]
    else:
        out = np.stack([np.interp(t, t_src, flat[:, i]) for i in range(flat.shape[1])], axis=1)
    return out.reshape((len(t), *x.shape[1:]))


def _derived_signals(md: Any) -> str:
    """Signals the log derived rather than measured (``RunMetadata.extra["derived_signals"]``, comma-separated).

    MPM-evaluation logs (``contact_model == "mpm"``) written before they declared it derive the accelerometer too.
    """
    derived = md.extra.get("derived_signals", "")
    return derived or ("imu.accelerometer" if md.contact_model == "mpm" else "")


def read_recording(path: str | Path, rate_hz: float | None = None) -> Recording:
    """Read a G1 MCAP log (``gmloco.deploy.logs.read_log``) onto a uniform grid.

    Samples farther than 1.5 periods from any LowState message are marked invalid (gaps).

    Args:
        path: MCAP file in the project schema (``packages/deploy/SCHEMA.md``).
        rate_hz: Grid rate [Hz]; the metadata's ``lowstate_rate_hz`` by default.

    Raises:
        ValueError: an unknown ``support`` label, besides the reader's own errors.
    """
    from gmloco.deploy.logs.reader import read_log

    log = read_log(path)
    support = support_from_label(log.metadata.support)
    rate = rate_hz or float(log.metadata.lowstate_rate_hz)
    ts, q = log.signal("lowstate.q")
    t = np.arange(ts[0], ts[-1] + 0.5 / rate, 1.0 / rate)
    near = np.abs(ts[np.clip(np.searchsorted(ts, t), 0, len(ts) - 1)] - t)
    near = np.minimum(near, np.abs(ts[np.clip(np.searchsorted(ts, t) - 1, 0, len(ts) - 1)] - t))
    get = lambda name, hold=False: _resample(*log.signal(name), t, hold)  # noqa: E731
    quat = get("imu.quaternion")
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    base_pos = base_quat = base_linvel = base_angvel = None
    if log.has("odom.position"):
        oq = get("odom.orientation")
        base_pos = get("odom.position")
        base_quat = oq / np.linalg.norm(oq, axis=1, keepdims=True)
        base_linvel = get("odom.linear_velocity")
        base_angvel = get("odom.angular_velocity")
    tau = get("lowstate.tau_est") if log.has("lowstate.tau_est") else np.zeros_like(_resample(ts, q, t, False))
    return Recording(
        t=t - t[0],
        q=get("lowstate.q"),
        dq=get("lowstate.dq"),
        tau_est=tau,
        q_cmd=get("lowcmd.q", True),
        dq_cmd=get("lowcmd.dq", True),
        kp=get("lowcmd.kp", True),
        kd=get("lowcmd.kd", True),
        tau_ff=get("lowcmd.tau", True),
        imu_quat=quat,
        imu_gyro=get("imu.gyroscope"),
        imu_acc=get("imu.accelerometer"),
        valid=near <= 1.5 / rate,
        meta={
            "path": str(path),
            "controller": log.metadata.controller,
            "robot": log.metadata.robot,
            "material": log.metadata.material,
            "derived_signals": _derived_signals(log.metadata),
        },
        base_pos=base_pos,
        base_quat=base_quat,
        base_linvel=base_linvel,
        base_angvel=base_angvel,
        support=support,
    )


def write_recording(rec: Recording, path: str | Path, controller: str = "unknown", overwrite: bool = False) -> Path:
    """Write a :class:`Recording` as a G1 MCAP log (``gmloco.deploy.logs.G1LogWriter``); invalid samples are dropped.

    The metadata's ``support`` is ``none`` for a free base, else the recording's ``gantry`` or ``fixed``.
    """
    from gmloco.deploy.logs.metadata import RunMetadata
    from gmloco.deploy.logs.writer import G1LogWriter, LogWriterCfg

    meta = RunMetadata(
        controller=controller,
        source="real",
        contact_model="hardware",
        lowstate_rate_hz=1.0 / rec.dt,
        support="none" if rec.support == "free" else rec.support,
    )
    valid = rec.valid_mask()
    odom = rec.odometry()
    with G1LogWriter(path, meta, LogWriterCfg(overwrite=overwrite)) as w:
        for k in range(rec.n):
            if not valid[k]:
                continue
            t = float(rec.t[k])
            w.write_lowstate(t, rec.q[k], rec.dq[k], rec.tau_est[k], rec.imu_quat[k], rec.imu_gyro[k], rec.imu_acc[k])
            w.write_lowcmd(t, rec.q_cmd[k], rec.dq_cmd[k], rec.kp[k], rec.kd[k], rec.tau_ff[k])
            if odom is not None:
                base_pos, base_quat, base_linvel, base_angvel = odom
                w.write_odometry(t, base_pos[k], base_quat[k], base_linvel[k], base_angvel[k])
    return Path(path)
