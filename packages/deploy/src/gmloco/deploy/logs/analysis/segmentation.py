# SPDX-License-Identifier: Apache-2.0
"""Stance/swing segmentation without foot sensors, from forward-kinematics foot heights.

The G1 has no foot force sensors, so contact is inferred. A foot is in stance while its sole is within
``touchdown_height`` of the lower foot's sole (heights in a gravity-aligned frame, from joint angles and the
IMU: :func:`~gmloco.deploy.logs.analysis.kinematics.sole_heights`), with hysteresis: it leaves stance only when
it rises above ``liftoff_height``. Phases shorter than ``min_phase_s`` are merged into their neighbours
(debounce). Relative heights need no base position; on sand both feet sink, so a uniform sinkage cancels,
while unequal sinkage biases touchdown late (documented limitation; a torque-based cue is an open item).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

__all__ = ["SegmentationCfg", "phase_windows", "relative_heights", "segment_stance"]


@dataclass
class SegmentationCfg:
    """Settings of :func:`segment_stance`."""

    touchdown_height: float = 0.01
    """A swinging foot lands when it comes within this height of the lower foot [m]."""
    liftoff_height: float = 0.02
    """A stance foot lifts off when it rises above this height over the lower foot [m]."""
    min_phase_s: float = 0.06
    """Stance or swing phases shorter than this are merged into their neighbours [s]."""


def relative_heights(heights: np.ndarray) -> np.ndarray:
    """Height of each foot above the lower foot [m], shape [T, 2] -> [T, 2]."""
    return heights - heights.min(axis=1, keepdims=True)


def _hysteresis(h: np.ndarray, on: float, off: float) -> np.ndarray:
    """Stance flags of one foot from its relative height [T] (starts in stance if below ``off``)."""
    out = np.zeros(len(h), dtype=bool)
    state = bool(h[0] < off) if len(h) else False
    for i, x in enumerate(h):
        if state and x > off:
            state = False
        elif not state and x < on:
            state = True
        out[i] = state
    return out


def _debounce(mask: np.ndarray, min_len: int) -> np.ndarray:
    """Flip runs shorter than ``min_len`` samples (interior runs only), shortest first."""
    m = mask.copy()
    while True:
        edges = np.flatnonzero(np.diff(m.astype(np.int8))) + 1
        bounds = np.concatenate([[0], edges, [len(m)]])
        lengths = np.diff(bounds)
        interior = np.arange(1, len(lengths) - 1)
        short = [i for i in interior if lengths[i] < min_len]
        if not short:
            return m
        i = min(short, key=lambda k: lengths[k])
        m[bounds[i] : bounds[i + 1]] = ~m[bounds[i]]


def segment_stance(t: np.ndarray, heights: np.ndarray, cfg: SegmentationCfg | None = None) -> np.ndarray:
    """Return stance flags per foot.

    Args:
        t: Time [s], shape [T], uniform.
        heights: Sole heights of (left, right) in a common gravity-aligned frame [m], shape [T, 2].
        cfg: Thresholds.

    Returns:
        Stance mask, shape [T, 2] (True = stance).
    """
    cfg = cfg or SegmentationCfg()
    rel = relative_heights(heights)
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    min_len = max(1, round(cfg.min_phase_s / dt))
    cols = [_debounce(_hysteresis(rel[:, k], cfg.touchdown_height, cfg.liftoff_height), min_len) for k in range(2)]
    return np.stack(cols, axis=1)


def phase_windows(mask: np.ndarray, value: bool = True, complete_only: bool = True) -> list[tuple[int, int]]:
    """Return ``[(i0, i1), ...]`` index windows (``i1`` exclusive) where ``mask == value``.

    Args:
        mask: Flags of one foot, shape [T].
        value: Which phase to return (True = stance, False = swing).
        complete_only: Drop windows touching the start or the end of the record (cut phases).
    """
    m = np.asarray(mask) == value
    edges = np.flatnonzero(np.diff(m.astype(np.int8))) + 1
    bounds = np.concatenate([[0], edges, [len(m)]])
    out = [(int(a), int(b)) for a, b in itertools.pairwise(bounds) if m[a]]
    if complete_only:
        out = [(a, b) for a, b in out if a > 0 and b < len(m)]
    return out
