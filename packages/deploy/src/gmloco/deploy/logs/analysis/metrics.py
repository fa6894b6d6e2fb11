# SPDX-License-Identifier: Apache-2.0
"""Gait metrics on aligned arrays: velocity tracking, ankle-pitch torque per stance, swing-foot clearance."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from gmloco.deploy.g1 import G1_FEET
from gmloco.deploy.logs.analysis.segmentation import phase_windows

__all__ = [
    "MetricsCfg",
    "command_segments",
    "segmentation_agreement",
    "stance_ankle_torque",
    "stance_profiles",
    "swing_clearance",
    "velocity_tracking",
]


@dataclass
class MetricsCfg:
    """Settings of the gait metrics."""

    settle_s: float = 1.0
    """Time after a command change excluded from tracking statistics [s]."""
    profile_points: int = 101
    """Samples of a stance-normalized torque profile (0..100 % of stance)."""


def command_segments(t: np.ndarray, cmd: np.ndarray) -> list[tuple[int, int]]:
    """Index windows ``(i0, i1)`` of constant, finite command values [T]."""
    finite = np.isfinite(cmd)
    change = np.flatnonzero((np.diff(cmd) != 0) | (np.diff(finite) != 0)) + 1
    bounds = np.concatenate([[0], change, [len(cmd)]])
    return [(int(a), int(b)) for a, b in itertools.pairwise(bounds) if b > a and finite[a]]


def velocity_tracking(t: np.ndarray, cmd: np.ndarray, v: np.ndarray, cfg: MetricsCfg | None = None) -> list[dict]:
    """Forward-velocity tracking per constant-command segment.

    Args:
        t: Time [s], [T].
        cmd: Commanded forward speed [m/s], [T].
        v: Measured (or estimated) forward speed, heading frame [m/s], [T].
        cfg: Settings.

    Returns:
        One dict per segment: ``cmd``, ``v_mean``, ``v_std``, ``error_mean`` (v - cmd), ``rmse`` [m/s],
        ``t_start``, ``t_end``, ``duration`` [s] of the evaluated (settled) part.
    """
    cfg = cfg or MetricsCfg()
    rows = []
    for a, b in command_segments(t, cmd):
        m = (t[a:b] >= t[a] + cfg.settle_s) & np.isfinite(v[a:b])
        if m.sum() < 2:
            continue
        vv, c = v[a:b][m], float(cmd[a])
        rows.append(
            {
                "cmd": c,
                "v_mean": float(vv.mean()),
                "v_std": float(vv.std()),
                "error_mean": float(vv.mean() - c),
                "rmse": float(np.sqrt(np.mean((vv - c) ** 2))),
                "t_start": float(t[a:b][m][0]),
                "t_end": float(t[a:b][m][-1]),
                "duration": float(t[a:b][m][-1] - t[a:b][m][0]),
            }
        )
    return rows


def stance_ankle_torque(t: np.ndarray, tau: np.ndarray, stance: np.ndarray) -> list[dict]:
    """Ankle-pitch torque statistics per complete stance.

    Args:
        t: Time [s], [T].
        tau: Ankle-pitch torque of (left, right) [N*m], [T, 2].
        stance: Stance flags, [T, 2].

    Returns:
        One dict per stance: ``foot``, ``t_start``, ``t_end`` [s], ``peak_abs``, ``mean`` [N*m], ``impulse`` [N*m*s].
    """
    rows = []
    for k, foot in enumerate(G1_FEET):
        for a, b in phase_windows(stance[:, k], True):
            x = tau[a:b, k]
            rows.append(
                {
                    "foot": foot,
                    "t_start": float(t[a]),
                    "t_end": float(t[b - 1]),
                    "peak_abs": float(np.nanmax(np.abs(x))),
                    "mean": float(np.nanmean(x)),
                    "impulse": float(np.sum(0.5 * (x[1:] + x[:-1]) * np.diff(t[a:b]))),
                }
            )
    return rows


def stance_profiles(tau: np.ndarray, stance: np.ndarray, points: int = 101) -> np.ndarray:
    """Stance-normalized torque profiles, shape [n_stances, points] (0..100 % of each stance)."""
    out = []
    for k in range(stance.shape[1]):
        for a, b in phase_windows(stance[:, k], True):
            if b - a >= 3:
                out.append(np.interp(np.linspace(0, 1, points), np.linspace(0, 1, b - a), tau[a:b, k]))
    return np.array(out).reshape(-1, points)


def swing_clearance(t: np.ndarray, rel_height: np.ndarray, stance: np.ndarray) -> list[dict]:
    """Peak height of the swing foot's sole over the other foot's sole, per complete swing.

    Args:
        t: Time [s], [T].
        rel_height: Sole height above the lower foot [m], [T, 2].
        stance: Stance flags, [T, 2].

    Returns:
        One dict per swing: ``foot``, ``t_start``, ``t_end``, ``t_peak`` [s], ``clearance`` [m].
    """
    rows = []
    for k, foot in enumerate(G1_FEET):
        for a, b in phase_windows(stance[:, k], False):
            i = a + int(np.nanargmax(rel_height[a:b, k]))
            rows.append(
                {
                    "foot": foot,
                    "t_start": float(t[a]),
                    "t_end": float(t[b - 1]),
                    "t_peak": float(t[i]),
                    "clearance": float(rel_height[i, k]),
                }
            )
    return rows


def segmentation_agreement(stance: np.ndarray, truth: np.ndarray) -> float:
    """Fraction of samples where estimated stance equals the simulator's contact truth (both feet)."""
    return float(np.mean(stance == truth))
