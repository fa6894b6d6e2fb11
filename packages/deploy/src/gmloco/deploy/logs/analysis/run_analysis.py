# SPDX-License-Identifier: Apache-2.0
"""Analyze one G1 log: align, segment, estimate base velocity, compute the gait metrics."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.logs.align import AlignCfg, AlignedLog
from gmloco.deploy.logs.analysis.base_velocity import (
    BaseVelocityCfg,
    heading_velocity_from_odometry,
    leg_odometry_velocity,
    smooth,
)
from gmloco.deploy.logs.analysis.kinematics import sole_heights
from gmloco.deploy.logs.analysis.metrics import (
    MetricsCfg,
    segmentation_agreement,
    stance_ankle_torque,
    stance_profiles,
    swing_clearance,
    velocity_tracking,
)
from gmloco.deploy.logs.analysis.segmentation import SegmentationCfg, relative_heights, segment_stance
from gmloco.deploy.logs.reader import G1Log, ReadCfg, read_log

__all__ = ["AnalysisCfg", "RunAnalysis", "analyze_log"]


@dataclass
class AnalysisCfg:
    """Settings of the log analyses."""

    rate_hz: float | None = 100.0
    """Common time base of the analysis [Hz]; ``None`` = the log's joint-state rate."""
    read: ReadCfg = field(default_factory=ReadCfg)
    """Reader settings."""
    segmentation: SegmentationCfg = field(default_factory=SegmentationCfg)
    """Stance/swing thresholds."""
    base_velocity: BaseVelocityCfg = field(default_factory=BaseVelocityCfg)
    """Base-velocity smoothing."""
    metrics: MetricsCfg = field(default_factory=MetricsCfg)
    """Metric settings."""


@dataclass
class RunAnalysis:
    """Results of one log (scalars in :attr:`summary`, per-event rows and time series for figures)."""

    path: Path
    """Analyzed file."""
    log: G1Log
    """The decoded log."""
    aligned: AlignedLog
    """Signals on the analysis time base."""
    summary: dict[str, Any]
    """One summary-table row."""
    tracking: list[dict]
    """Velocity tracking per command segment."""
    stances: list[dict]
    """Ankle-pitch torque per stance."""
    swings: list[dict]
    """Clearance per swing."""
    series: dict[str, np.ndarray]
    """Time series for figures: ``t``, ``rel_height`` [T, 2], ``stance`` [T, 2], ``v_fwd``, ``cmd_vx``,
    ``ankle_profiles`` [n, 101], optional ``contact_truth`` [T, 2], ``eta`` [T, K]."""


def _base_velocity(a: AlignedLog, stance: np.ndarray, cfg: AnalysisCfg) -> tuple[np.ndarray, str, np.ndarray | None]:
    """Return smoothed forward velocity [m/s], its source, and the leg-odometry estimate (for validation)."""
    v_leg = leg_odometry_velocity(a.t, a["lowstate.q"], a["imu.quaternion"], a["imu.gyroscope"], stance)
    v_leg = smooth(a.t, v_leg[:, 0], cfg.base_velocity.window_s)
    if "odom.linear_velocity" in a and "odom.orientation" in a:
        v = heading_velocity_from_odometry(a["odom.orientation"], a["odom.linear_velocity"])
        return smooth(a.t, v[:, 0], cfg.base_velocity.window_s), "odometry", v_leg
    return v_leg, "leg_odometry", None


def _nanmean(rows: list[dict], key: str) -> float:
    """Mean of a key over rows, NaN when empty."""
    return float(np.mean([r[key] for r in rows])) if rows else float("nan")


def analyze_log(path: str | Path, cfg: AnalysisCfg | None = None) -> RunAnalysis:
    """Run every analysis on one log."""
    cfg = cfg or AnalysisCfg()
    log = read_log(path, cfg.read)
    a = log.aligned(AlignCfg(rate_hz=cfg.rate_hz))
    heights = sole_heights(a["lowstate.q"], a["imu.quaternion"])
    stance = segment_stance(a.t, heights, cfg.segmentation)
    rel = relative_heights(heights)
    v_fwd, v_source, v_leg = _base_velocity(a, stance, cfg)
    cmd = a["command.lin_vel_x"] if "command.lin_vel_x" in a else np.full(len(a.t), np.nan)
    tracking = velocity_tracking(a.t, cmd, v_fwd, cfg.metrics)
    ankle = np.stack([a.joint(f"{f}_ankle_pitch_joint", "lowstate.tau_est") for f in ("left", "right")], 1)
    stances = stance_ankle_torque(a.t, ankle, stance)
    swings = swing_clearance(a.t, rel, stance)
    series = {"t": a.t, "rel_height": rel, "stance": stance, "v_fwd": v_fwd, "cmd_vx": cmd, "ankle_pitch_tau": ankle}
    series["ankle_profiles"] = stance_profiles(ankle, stance, cfg.metrics.profile_points)
    m = log.metadata
    summary: dict[str, Any] = {
        "file": Path(path).name,
        "source": m.source,
        "controller": m.controller,
        "policy": m.policy,
        "material": m.material,
        "support": m.support.split("(")[0],
        "duration_s": float(a.t[-1] - a.t[0]),
        "damaged": bool(log.damage),
        "velocity_source": v_source,
        "n_stances": len(stances),
        "n_swings": len(swings),
        "stance_duration_s": _nanmean([{"d": s["t_end"] - s["t_start"]} for s in stances], "d"),
        "ankle_pitch_peak_Nm": _nanmean(stances, "peak_abs"),
        "ankle_pitch_impulse_Nms": _nanmean(stances, "impulse"),
        "clearance_mean_m": _nanmean(swings, "clearance"),
        "clearance_std_m": float(np.std([s["clearance"] for s in swings])) if swings else float("nan"),
        "tracking_rmse_mps": _nanmean(tracking, "rmse"),
    }
    if v_leg is not None:
        ok = np.isfinite(v_leg) & np.isfinite(v_fwd)
        summary["leg_odometry_rmse_mps"] = float(np.sqrt(np.mean((v_leg[ok] - v_fwd[ok]) ** 2))) if ok.any() else None
    if "sim.in_contact" in a:
        series["contact_truth"] = a["sim.in_contact"]
        summary["segmentation_agreement"] = segmentation_agreement(stance, a["sim.in_contact"])
    if "student.eta" in a:
        series["eta"] = a["student.eta"]
        eta = a["student.eta"]
        summary["eta_mean"] = [float(x) for x in np.nanmean(eta, axis=0)]
        summary["eta_names"] = log.channels["/student/eta"].metadata.get("names", "")
    return RunAnalysis(Path(path), log, a, summary, tracking, stances, swings, series)
