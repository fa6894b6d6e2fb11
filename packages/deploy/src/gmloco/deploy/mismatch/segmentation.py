# SPDX-License-Identifier: Apache-2.0
"""Stance/swing segmentation from kinematic foot heights (no foot force sensor on the G1).

A foot is in stance while its lowest sole point is within ``stance_height`` of the lower foot (hysteresis
``release_height``), from leg-odometry foot heights (:mod:`gmloco.deploy.mismatch.baseest`). Each foot's
samples are labelled ``swing``, ``touchdown`` (first ``td_window`` of stance), ``liftoff`` (last
``lo_window`` of stance) or ``stance``. Sinkage on sand biases height-based detection; the hysteresis band
absorbs a few millimetres of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PHASES", "SegmentationCfg", "segment_phases"]

PHASES: tuple[str, ...] = ("swing", "touchdown", "stance", "liftoff")
"""Per-foot phase labels, indexed by the integer codes returned by :func:`segment_phases`."""


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
