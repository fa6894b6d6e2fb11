# SPDX-License-Identifier: Apache-2.0
"""Stance/swing segmentation from kinematic foot heights (no foot force sensor on the G1).

A foot is in stance while its lowest sole point is within ``stance_height`` of the lower foot (hysteresis
``release_height``), from leg-odometry foot heights (:mod:`gmloco.deploy.mismatch.baseest`). Each foot's
samples are labelled ``swing``, ``touchdown`` (first ``td_window`` of stance), ``liftoff`` (last
``lo_window`` of stance) or ``stance``. Sinkage on sand biases height-based detection; the hysteresis band
absorbs a few millimetres of it.

A held pelvis (``support`` gantry or fixed) touches nothing, so contact phases mean nothing there:
:func:`motion_phases` labels each joint by its commanded motion instead (``hold``, ``low_freq``, ``high_freq``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MOTION_PHASES", "PHASES", "SegmentationCfg", "motion_phases", "segment_phases"]

PHASES: tuple[str, ...] = ("swing", "touchdown", "stance", "liftoff")
"""Per-foot phase labels, indexed by the integer codes returned by :func:`segment_phases`."""
MOTION_PHASES: tuple[str, ...] = ("hold", "low_freq", "high_freq")
"""Per-joint labels of a held robot, indexed by the codes of :func:`motion_phases`."""


@dataclass
class SegmentationCfg:
    """Thresholds of the height-based contact detector."""

    stance_height: float = 0.006
    """A foot within this height of the lower one is (or becomes) in stance [m]."""
    release_height: float = 0.012
    """A stance foot is released to swing above this height [m]."""
    td_window: float = 0.06
    """Touchdown window after contact onset [s]."""
    lo_window: float = 0.06
    """Lift-off window before contact release [s]."""
    motion_window: float = 0.5
    """Window over which a joint command's speed and frequency are measured (held pelvis) [s]: half a period of
    1 Hz, so the estimate is exact at 1 Hz and never reaches ``split_frequency`` below it."""
    hold_speed: float = 0.02
    """A joint whose commanded speed (RMS over the window) is below this holds still [rad/s]."""
    split_frequency: float = 2.0
    """Commanded motion above this local frequency is ``high_freq`` [Hz]."""


def segment_phases(foot_height: np.ndarray, dt: float, cfg: SegmentationCfg | None = None) -> np.ndarray:
    """Return per-foot phase codes (indices into :data:`PHASES`), shape [N, 2].

    Args:
        foot_height: Lowest sole-point height of each foot relative to the support foot [m], shape [N, 2].
        dt: Sample period [s].
        cfg: Thresholds.
    """
    cfg = cfg or SegmentationCfg()
    n = len(foot_height)
    rel = foot_height - foot_height.min(axis=1, keepdims=True)
    out = np.zeros((n, 2), dtype=int)
    for f in range(2):
        stance = np.zeros(n, bool)
        s = True
        for k in range(n):
            s = rel[k, f] < (cfg.release_height if s else cfg.stance_height)
            stance[k] = s
        lab = np.where(stance, 2, 0)
        edges = np.flatnonzero(np.diff(stance.astype(int)))
        w_td, w_lo = round(cfg.td_window / dt), round(cfg.lo_window / dt)
        for e in edges:
            if stance[e + 1]:
                seg = slice(e + 1, min(n, e + 1 + w_td))
                lab[seg] = np.where(stance[seg], 1, lab[seg])
            else:
                seg = slice(max(0, e + 1 - w_lo), e + 1)
                lab[seg] = np.where(stance[seg], 3, lab[seg])
        out[:, f] = lab
    return out


def motion_phases(q_cmd: np.ndarray, dt: float, cfg: SegmentationCfg | None = None) -> np.ndarray:
    """Label each joint's samples by its commanded motion, for a robot that touches nothing, shape [N, J].

    The local frequency of the command is ``sqrt(<qdd^2> / <qd^2>) / 2 pi`` over ``motion_window`` (exact for a
    sinusoid, ``A sin(w t)``: the ratio is ``w^2``); codes index :data:`MOTION_PHASES`: ``hold`` where the RMS
    commanded speed is below ``hold_speed``, else ``low_freq`` or ``high_freq`` about ``split_frequency``.

    Args:
        q_cmd: Commanded joint positions [rad], shape [N, J].
        dt: Sample period [s].
        cfg: Thresholds.
    """
    cfg = cfg or SegmentationCfg()
    n = len(q_cmd)
    qd = np.gradient(q_cmd, dt, axis=0) if n > 1 else np.zeros_like(q_cmd)
    qdd = np.gradient(qd, dt, axis=0) if n > 1 else np.zeros_like(q_cmd)
    w = int(min(n, max(1, round(cfg.motion_window / dt))))
    kernel = np.ones(w) / w
    smooth = lambda x: np.apply_along_axis(lambda c: np.convolve(c, kernel, mode="same"), 0, x)  # noqa: E731
    v2, a2 = smooth(qd**2), smooth(qdd**2)
    freq = np.sqrt(a2 / np.maximum(v2, 1e-300)) / (2.0 * np.pi)
    out = np.where(freq > cfg.split_frequency, 2, 1)
    return np.where(np.sqrt(v2) < cfg.hold_speed, 0, out)
