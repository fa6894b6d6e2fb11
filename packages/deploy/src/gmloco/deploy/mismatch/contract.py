# SPDX-License-Identifier: Apache-2.0
"""Data-contract checks: joint map, units, time base, gaps, support. Failures are reported as such, never as physics.

Severity ``error`` is a contract doubt: the analysis stops with the verdict ``invalid_input`` (exit code 2 from
the command line). Severity ``warning`` is a condition the analysis handles and states (gap-filled samples
skipped, a missing or derived channel left out of the residual).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import asdict, dataclass, field
from functools import lru_cache
from typing import Literal

import numpy as np

from gmloco.deploy.g1 import g1_mjcf_path
from gmloco.deploy.mismatch.frames import quat_conj, quat_mul, quat_to_mat
from gmloco.deploy.mismatch.recording import Recording

__all__ = [
    "ContractCfg",
    "ContractError",
    "ContractIssue",
    "JointMapError",
    "base_motion",
    "check_recording",
    "joint_ranges",
]


@dataclass
class ContractIssue:
    """One finding of a contract check."""

    check: str
    """Check name (``joint_map``, ``units``, ``time_base``, ``gaps``, ``channels``, ``length``, ``support``)."""
    severity: Literal["error", "warning"]
    """Errors stop the analysis; warnings are reported."""
    message: str
    """What is wrong and how to fix it."""
    detail: dict = field(default_factory=dict)
    """Machine-readable evidence."""

    def to_dict(self) -> dict:
        """JSON-ready form."""
        return asdict(self)


class ContractError(ValueError):
    """The recording breaks the data contract; :attr:`issues` says how."""

    def __init__(self, issues: list[ContractIssue]) -> None:
        """Keep the issues and format them."""
        self.issues = issues
        super().__init__("; ".join(f"[{i.check}] {i.message}" for i in issues if i.severity == "error"))


class JointMapError(ContractError):
    """Joint columns do not belong to the joints they are labelled with."""


@dataclass
class ContractCfg:
    """Thresholds of the contract checks."""

    range_slack: float = 0.15
    """Allowed excursion beyond the MJCF joint range [rad]."""
    map_ratio: float = 0.5
    """A command column matches another state column this much better (median distance ratio) -> map error."""
    map_min_error: float = 0.08
    """Median |q_cmd - q| above which a joint's pairing is questioned [rad]."""
    jitter_max: float = 0.2
    """Largest tolerated std(dt) / median(dt) [-]."""
    min_duration: float = 2.0
    """Shorter recordings cannot be analysed [s]."""
    quat_gravity_bad: float = 0.5
    """Median angle between the accelerometer and the quaternion's up direction above which a reading of the IMU
    quaternion is inconsistent with gravity [rad] (about 29 deg)."""
    quat_gravity_good: float = 0.2
    """Median angle below which a reading of the IMU quaternion is consistent with gravity [rad] (about 11 deg)."""
    quat_gravity_window: float = 0.25
    """Moving-average window of the accelerometer and the up direction before they are compared: averages out the
    body's own accelerations over a step, which leave gravity [s]."""
    quat_rate_window: float = 0.04
    """Window over which the quaternion's rotation rate is compared with the gyro [s]."""
    quat_rate_min: float = 0.1
    """Gyro activity (RMS about its median) below which the rate comparison is not used [rad/s]."""
    quat_rate_ratio: float = 3.0
    """One reading decides on the rate test when its gyro misfit is this many times smaller than the other's and
    below half the gyro activity [-]."""
    motion_window: float = 0.02
    """Moving-average window of the joint velocities and the IMU before the support check (removes sensor
    noise) [s]."""
    legs_active: float = 2.0
    """RMS leg and waist joint acceleration above which the legs move enough to test the support [rad/s^2]."""
    still_acc_per_joint_acc: float = 0.02
    """A free pelvis whose legs accelerate is shaken by them: the IMU is still when its specific force varies
    less than this per unit of joint acceleration (RMS) [m/rad]. Free G1 recordings (standing with arm motion,
    stepping, walking, the policy on sand) show 0.24-0.59; a pelvis held while the legs chirp 0.001."""
    still_gyro: float = 0.05
    """... and when its gyro varies less than this (RMS about the median) [rad/s]."""
    moving_gyro: float = 0.05
    """A held pelvis moves when the gyro varies more than this (RMS about the median) [rad/s]."""
    moving_acc: float = 0.3
    """... or when the specific force varies more than this (RMS about the median) [m/s^2]."""


@lru_cache(maxsize=1)
def joint_ranges() -> dict[str, tuple[float, float]]:
    """Joint ranges [rad] read from mjlab's G1 MJCF (plain XML parsing, no mujoco import)."""
    root = ET.parse(g1_mjcf_path()).getroot()
    out: dict[str, tuple[float, float]] = {}
    for j in root.iter("joint"):
        name, rng = j.get("name"), j.get("range")
        if rng and name:
            lo, hi = (float(x) for x in rng.split())
            out[name] = (lo, hi)
    return out


def _joint_map(rec: Recording, cfg: ContractCfg) -> list[ContractIssue]:
    """Ranges and command/state pairing per joint."""
    issues = []
    ranges = joint_ranges()
    out_of_range = []
    for i, n in enumerate(rec.joint_names):
        lo, hi = ranges.get(n, (-np.inf, np.inf))
        frac = float(np.mean((rec.q[:, i] < lo - cfg.range_slack) | (rec.q[:, i] > hi + cfg.range_slack)))
        if frac > 0.05:
            out_of_range.append((n, round(frac, 3)))
    dist = np.median(np.abs(rec.q_cmd[:, :, None] - rec.q[:, None, :]), axis=0)  # [cmd joint, state joint]
    corr = _xcorr(rec.q_cmd, rec.q)
    pd_ok, pd_swap, pd_best = _pd_pairing(rec)
    swaps = []
    for j, n in enumerate(rec.joint_names):
        if pd_ok[j] and not pd_swap[j]:
            # The motor law ties this column's command, state and tau_est together: the pairing is right even
            # when a low-gain policy's targets sit far from the measured positions (the distance/correlation
            # heuristics below would then misfire).
            continue
        k = int(np.argmin(dist[j]))
        c = int(np.nanargmax(corr[j])) if np.any(np.isfinite(corr[j])) else j
        # Distance alone is fooled by joints with similar set-points under load sag: it needs the
        # correlation to agree, or a gross error when the command is constant (correlation undefined).
        by_dist = k != j and dist[j, j] > cfg.map_min_error and dist[j, k] < cfg.map_ratio * dist[j, j]
        if np.isfinite(corr[j, j]) and np.isfinite(corr[j, k]):
            by_dist = by_dist and corr[j, k] > corr[j, j] + 0.2
        else:
            by_dist = by_dist and dist[j, j] > 3 * cfg.map_min_error
        by_corr = c != j and corr[j, c] > 0.8 and not corr[j, j] > 0.5
        if pd_swap[j] or by_dist or by_corr:
            m = int(pd_best[j]) if pd_swap[j] else k if by_dist else c
            swaps.append(
                {
                    "command": n,
                    "state_column_matching": rec.joint_names[m],
                    "median_err_rad": round(float(dist[j, j]), 3),
                }
            )
    if swaps or out_of_range:
        msg = "joint columns do not match their labels: "
        if swaps:
            msg += (
                "commands track other state columns "
                + ", ".join(f"{s['command']}->{s['state_column_matching']}" for s in swaps)
                + ". "
            )
        if out_of_range:
            msg += f"positions outside the MJCF range: {out_of_range}. "
        msg += "Fix the joint order (Unitree motor index order, see gmloco.deploy.logs.g1.G1_JOINT_NAMES)."
        issues.append(ContractIssue("joint_map", "error", msg, {"swaps": swaps, "out_of_range": out_of_range}))
    return issues


def _pd_pairing(rec: Recording, min_corr: float = 0.9) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pair each command column with a state column through the motor law ``tau_est = kp (q* - q) + kd (dq* - dq)``.

    For command joint j and state column k, ``err[j, k]`` is the relative misfit of tau_est_j by the PD torque
    built from state column k, after the best gain scale: ``sqrt(1 - c^2)`` with c the uncentred correlation
    (a gain error or a torque-constant error rescales tau_est and must not look like a swap). Returns three [29]
    arrays: ``ok`` (the labelled column fits best, within 10 %, with c > ``min_corr``), ``swap`` (another column
    fits with less than half the labelled misfit and c > ``min_corr``) and the best column. ``ok`` and ``swap``
    are False where tau_est is not logged or does not vary.

    The command in force at a logged state is either the one logged with it or the one before it
    (:func:`_command_lag`); the pairing uses the lag under which the motor law fits the recording best.
    """
    ok, swap, bests = np.zeros(29, bool), np.zeros(29, bool), np.arange(29)
    if np.allclose(rec.tau_est, 0.0):
        return ok, swap, bests
    lag = _command_lag(rec)
    n = rec.n - lag
    base = (rec.kp * rec.q_cmd + rec.kd * rec.dq_cmd + rec.tau_ff)[:n]  # [N - lag, 29], the command in force
    kp, kd, q, dq, tau_est = rec.kp[:n], rec.kd[:n], rec.q[lag:], rec.dq[lag:], rec.tau_est[lag:]
    for j in range(29):
        tau = tau_est[:, j]
        if tau.std() < 1e-3:
            continue
        pd = base[:, j : j + 1] - kp[:, j : j + 1] * q - kd[:, j : j + 1] * dq  # [N - lag, 29 cols]
        c = (tau @ pd) / np.maximum(np.sqrt((tau @ tau) * np.sum(pd * pd, axis=0)), 1e-300)
        err = np.sqrt(np.clip(1.0 - c * c, 0.0, None))
        best = bests[j] = int(np.argmin(err))
        ok[j] = err[j] <= 1.1 * err[best] + 1e-9 and c[j] > min_corr
        swap[j] = best != j and err[best] < 0.5 * err[j] and c[best] > min_corr
    return ok, swap, bests


def _command_lag(rec: Recording) -> int:
    """Samples between a logged command and the logged state whose tau_est it produced: 0 or 1.

    A motor applies the latest command it has received, so the tau_est logged with a state comes from the command
    sent one control tick earlier whenever command and state are logged on the same tick (the project's 50 Hz
    simulator recordings: the state of step i, then the target sent for [t_i, t_i+1)). At 500 Hz the two readings
    hardly differ; at 50 Hz the same-sample reading misfits joints whose target moves more per step than they lag
    it (the wrists), and an unrelated column can then fit better and look like a swap. The lag whose labelled
    columns fit the motor law best (median misfit over the joints) is taken.
    """
    misfit = []
    for lag in (0, 1):
        n = rec.n - lag
        pd = rec.kp[:n] * (rec.q_cmd[:n] - rec.q[lag:]) + rec.kd[:n] * (rec.dq_cmd[:n] - rec.dq[lag:])
        res = rec.tau_est[lag:] - pd - rec.tau_ff[:n]
        scale = np.maximum(np.linalg.norm(rec.tau_est[lag:], axis=0), 1e-9)
        misfit.append(float(np.median(np.linalg.norm(res, axis=0) / scale)))
    return int(np.argmin(misfit))


def _xcorr(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Correlation matrix between the columns of ``a`` and ``b`` (NaN for constant columns), shape [29, 29]."""
    az = a - a.mean(0)
    bz = b - b.mean(0)
    sa, sb = az.std(0), bz.std(0)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = (az.T @ bz) / len(a) / np.outer(sa, sb)
    c[sa < 1e-3, :] = np.nan
    return c


def _units(rec: Recording, cfg: ContractCfg) -> list[ContractIssue]:
    """Degrees for radians, g for m/s^2, quaternion order (:func:`_quat_order`) and norm."""
    issues = []
    if np.nanmax(np.abs(rec.q)) > 2 * np.pi:
        issues.append(ContractIssue("units", "error", "joint positions exceed 2*pi: degrees logged as radians?"))
    acc = float(np.nanmedian(np.linalg.norm(rec.imu_acc, axis=1)))
    if not 6.0 < acc < 14.0:
        issues.append(
            ContractIssue(
                "units",
                "error",
                f"median |accelerometer| = {acc:.2f}, expected ~9.81 m/s^2 (g units?)",
                {"acc_norm": acc},
            )
        )
    qn = np.linalg.norm(rec.imu_quat, axis=1)
    if np.nanmax(np.abs(qn - 1.0)) > 0.05:
        issues.append(ContractIssue("units", "error", "IMU quaternion is not unit norm"))
    else:
        swapped, evidence = _quat_order(rec.imu_quat, rec.imu_gyro, rec.imu_acc, rec.dt, cfg)
        if swapped:
            issues.append(
                ContractIssue(
                    "units", "error", "IMU quaternion looks (x, y, z, w); the schema is (w, x, y, z)", evidence
                )
            )
    if np.nanmedian(np.abs(rec.imu_gyro)) > 5.0:
        issues.append(ContractIssue("units", "error", "gyro magnitudes look like deg/s; the schema is rad/s"))
    return issues


def _quat_order(quat: np.ndarray, gyro: np.ndarray, acc: np.ndarray, dt: float, cfg: ContractCfg) -> tuple[bool, dict]:
    """Whether the IMU quaternion columns are (x, y, z, w) rather than the schema's (w, x, y, z).

    Both readings of the columns (as given, and re-read as x, y, z, w) are tested against the other IMU channels
    with quantities that do not depend on the heading (a turning robot must pass whatever its yaw):

    * gravity: the median angle between the accelerometer (specific force, up at rest) and the up direction in
      the IMU frame implied by the reading, ``R(q)^T e_z``, both averaged over ``quat_gravity_window``;
    * rate: the RMS misfit between the gyro and the body rotation rate of the reading, from
      ``q(k)^-1 q(k + m)`` over ``quat_rate_window`` (a constant gyro bias removed by the median), used only when
      the gyro moves (RMS above ``quat_rate_min``).

    A test favours a reading when that reading fits and the other does not. The order is reported wrong only when
    a test favours (x, y, z, w) and none favours (w, x, y, z); a recording that is uninformative (standing still
    at a heading where both readings look upright) passes.

    Returns:
        ``(swapped, evidence)`` with the per-reading misfits in ``evidence``.
    """
    readings = {"wxyz": np.asarray(quat, float), "xyzw": np.asarray(quat, float)[:, [3, 0, 1, 2]]}
    n = len(quat)
    if n < 3 or dt <= 0.0:
        return False, {}
    m = max(1, round(cfg.quat_rate_window / dt))
    w = min(n, max(1, round(cfg.quat_gravity_window / dt)))

    def _avg(x: np.ndarray) -> np.ndarray:
        """Moving average over ``w`` samples ('valid' part)."""
        c = np.concatenate([np.zeros((1, x.shape[1])), np.cumsum(x, axis=0)])
        return (c[w:] - c[:-w]) / w

    a_avg = _avg(np.asarray(acc, float))
    activity = float(np.sqrt(np.mean((gyro - np.median(gyro, axis=0)) ** 2))) if n > m else 0.0
    grav, rate = {}, {}
    for name, q in readings.items():
        q = q / np.linalg.norm(q, axis=1, keepdims=True)
        up = _avg(quat_to_mat(q)[:, 2, :])  # world z in the IMU frame
        cos = np.sum(up * a_avg, axis=1) / np.maximum(np.linalg.norm(up, axis=1) * np.linalg.norm(a_avg, axis=1), 1e-9)
        grav[name] = float(np.median(np.arccos(np.clip(cos, -1.0, 1.0))))
        if n > m:
            rel = quat_mul(quat_conj(q[:-m]), q[m:])
            rel = rel * np.where(rel[:, :1] < 0.0, -1.0, 1.0)
            sn = np.linalg.norm(rel[:, 1:], axis=1, keepdims=True)
            ang = 2.0 * np.arctan2(sn, rel[:, :1])
            w_q = np.where(sn > 1e-12, rel[:, 1:] / np.maximum(sn, 1e-300) * ang, 2.0 * rel[:, 1:]) / (m * dt)
            csum = np.concatenate([np.zeros((1, 3)), np.cumsum(gyro, axis=0)])
            mean_gyro = (csum[m:n] - csum[: n - m] + csum[m + 1 :] - csum[1 : n - m + 1]) / (2 * m)  # trapezoid
            res = mean_gyro - w_q
            rate[name] = float(np.sqrt(np.mean((res - np.median(res, axis=0)) ** 2)))
    votes = set()
    for good, bad in (("wxyz", "xyzw"), ("xyzw", "wxyz")):
        if grav[good] < cfg.quat_gravity_good and grav[bad] > cfg.quat_gravity_bad:
            votes.add(good)
        if (
            rate
            and activity > cfg.quat_rate_min
            and rate[good] < 0.5 * activity
            and rate[bad] > cfg.quat_rate_ratio * rate[good]
        ):
            votes.add(good)
    evidence = {
        "gravity_angle_rad": {k: round(v, 3) for k, v in grav.items()},
        "gyro_misfit_rad_s": {k: round(v, 3) for k, v in rate.items()},
        "gyro_activity_rad_s": round(activity, 3),
    }
    return votes == {"xyzw"}, evidence


def _time_base(rec: Recording, cfg: ContractCfg) -> list[ContractIssue]:
    """Monotonic uniform time base, gaps, duration."""
    issues = []
    d = np.diff(rec.t)
    if rec.n < 3 or np.any(d <= 0):
        return [ContractIssue("time_base", "error", "timestamps are not strictly increasing")]
    jitter = float(np.std(d) / np.median(d))
    if jitter > cfg.jitter_max:
        issues.append(
            ContractIssue("time_base", "error", f"non-uniform sampling (std/median dt = {jitter:.2f}); resample first")
        )
    gaps = float(np.mean(~rec.valid_mask()))
    if gaps > 0:
        issues.append(
            ContractIssue(
                "gaps",
                "warning",
                f"{100 * gaps:.2f}% of samples are gap-filled; segments across gaps are skipped",
                {"fraction": gaps},
            )
        )
    dur = float(rec.t[-1] - rec.t[0])
    if dur < cfg.min_duration:
        issues.append(
            ContractIssue(
                "length",
                "error",
                f"recording lasts {dur:.2f} s < {cfg.min_duration} s: too short to test any effect",
                {"duration_s": dur},
            )
        )
    return issues


def _channels(rec: Recording) -> list[ContractIssue]:
    """Non-finite values and constant channels."""
    issues = []
    for name in ("q", "dq", "tau_est", "q_cmd", "kp", "kd", "imu_quat", "imu_gyro", "imu_acc"):
        a = getattr(rec, name)
        if not np.all(np.isfinite(a)):
            issues.append(ContractIssue("channels", "error", f"{name} has non-finite values (missing channel?)"))
    if np.all(rec.kp == 0):
        issues.append(
            ContractIssue("channels", "error", "all kp are zero: LowCmd missing or torque-only control (not supported)")
        )
    if np.allclose(rec.tau_est, 0):
        issues.append(
            ContractIssue(
                "channels", "warning", "tau_est is all zero: torque channels excluded", {"tau_est": "missing"}
            )
        )
    if rec.acc_derived:
        issues.append(
            ContractIssue(
                "channels",
                "warning",
                "imu.accelerometer is derived (a finite difference of the logged velocity, as in the MPM evaluation's "
                "recordings), not a sensor: acc channels excluded",
                {"imu_acc": "derived"},
            )
        )
    return issues


def _moving_average(x: np.ndarray, w: int) -> np.ndarray:
    """Moving average over ``w`` samples ('valid' part), shape [N - w + 1, C]."""
    c = np.concatenate([np.zeros((1, x.shape[1])), np.cumsum(x, axis=0)])
    return (c[w:] - c[:-w]) / w


def base_motion(rec: Recording, cfg: ContractCfg) -> dict[str, float]:
    """How much the pelvis and the legs move: RMS variations of the smoothed IMU, and of the joint accelerations.

    Returns:
        ``acc_rms`` [m/s^2] and ``gyro_rms`` [rad/s] about their medians, and ``joint_acc_rms`` [rad/s^2] of the
        legs and waist (central difference of the smoothed joint velocities).
    """
    w = int(max(1, min(rec.n // 4, round(cfg.motion_window / rec.dt))))
    acc, gyro = _moving_average(rec.imu_acc, w), _moving_average(rec.imu_gyro, w)
    dq = _moving_average(rec.dq[:, :15], w)
    qdd = (dq[2 * w :] - dq[: -2 * w]) / (2 * w * rec.dt) if len(dq) > 2 * w else np.zeros((1, 15))
    dev = lambda x: float(np.sqrt(np.mean(np.sum((x - np.median(x, axis=0)) ** 2, axis=1))))  # noqa: E731
    return {"acc_rms": dev(acc), "gyro_rms": dev(gyro), "joint_acc_rms": float(np.sqrt(np.mean(qdd**2)))}


def _support(rec: Recording, cfg: ContractCfg) -> list[ContractIssue]:
    """The support the replay will simulate against what the IMU says about the pelvis.

    A free pelvis is shaken by legs that accelerate, whether the feet stand on the ground or swing; an IMU that
    stays still meanwhile says the pelvis is held, and a free replay would let it fall. A held pelvis (gantry,
    fixed) must not move. A recording whose legs barely move tests nothing here: a robot standing still on its
    feet and one hanging still look alike to the IMU.
    """
    m = base_motion(rec, cfg)
    detail = {k: round(v, 4) for k, v in m.items()} | {"support": rec.support}
    if rec.support == "free":
        still = m["acc_rms"] < cfg.still_acc_per_joint_acc * m["joint_acc_rms"] and m["gyro_rms"] < cfg.still_gyro
        if m["joint_acc_rms"] > cfg.legs_active and still:
            return [
                ContractIssue(
                    "support",
                    "error",
                    f"support is 'free' but the IMU says the pelvis is still (specific force varies "
                    f"{m['acc_rms']:.3f} m/s^2 RMS, gyro {m['gyro_rms']:.4f} rad/s) while the leg and waist joints "
                    f"accelerate at {m['joint_acc_rms']:.1f} rad/s^2 RMS: the pelvis was held, and a free replay "
                    "would let the simulated robot fall. Write support='gantry' (or 'fixed') in the run metadata, "
                    "or pass --support gantry",
                    detail,
                )
            ]
    elif m["gyro_rms"] > cfg.moving_gyro or m["acc_rms"] > cfg.moving_acc:
        return [
            ContractIssue(
                "support",
                "error",
                f"support is '{rec.support}' but the IMU says the pelvis moves (gyro varies {m['gyro_rms']:.3f} "
                f"rad/s RMS, specific force {m['acc_rms']:.2f} m/s^2): a welded replay would hold it still. Write "
                "support='none' in the run metadata for a robot on its own feet, or pass --support free",
                detail,
            )
        ]
    return []


def check_recording(rec: Recording, cfg: ContractCfg | None = None, raise_on_error: bool = True) -> list[ContractIssue]:
    """Run every contract check.

    Raises:
        JointMapError: If the joint map check fails (reported before any physics).
        ContractError: On any other error-severity issue.
    """
    cfg = cfg or ContractCfg()
    issues = _channels(rec)
    if not any(i.severity == "error" for i in issues):
        issues += _time_base(rec, cfg) + _units(rec, cfg) + _joint_map(rec, cfg)
    if not any(i.severity == "error" for i in issues):
        issues += _support(rec, cfg)
    errors = [i for i in issues if i.severity == "error"]
    if raise_on_error and errors:
        cls = JointMapError if any(i.check == "joint_map" for i in errors) else ContractError
        raise cls(issues)
    return issues
