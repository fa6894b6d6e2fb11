# SPDX-License-Identifier: Apache-2.0
"""Resample a log's signals onto one time base.

States (joint states, IMU, odometry) are interpolated linearly, quaternions by normalized lerp after making
consecutive samples sign-consistent, and piecewise-constant streams (commands, policy I/O, eta, contact flags)
by zero-order hold. A grid point farther than ``max_gap_s`` from the surrounding samples of a state channel
(dropped data, damage) and grid points outside a channel's span are NaN.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from gmloco.deploy.g1 import G1_JOINT_NAMES, joint_index
from gmloco.deploy.logs.rotations import quat_normalize
from gmloco.deploy.logs.schema import TOPIC_JOINT_STATES, signal_spec

if TYPE_CHECKING:
    from gmloco.deploy.logs.reader import G1Log

__all__ = ["AlignCfg", "AlignedLog", "align", "resample"]


@dataclass
class AlignCfg:
    """Settings of :func:`align`."""

    rate_hz: float | None = None
    """Rate of the common time base [Hz]; ``None`` uses the median rate of ``/lowstate/joint_states``."""
    signals: tuple[str, ...] | None = None
    """Signals to resample; ``None`` means every signal present."""
    t_start: float | None = None
    """Start of the time base [s since t0]; ``None`` = first joint-state sample."""
    t_end: float | None = None
    """End of the time base [s since t0]; ``None`` = last joint-state sample."""
    max_gap_s: float = 0.1
    """State samples farther apart than this are not interpolated across [s]."""
    hold_max_age_s: float = 1.0
    """A held value older than this becomes NaN [s] (a command stream that stopped)."""


@dataclass
class AlignedLog:
    """Signals on one time base."""

    t: np.ndarray
    """Time [s] since the log's ``t0``, shape [T]."""
    signals: dict[str, np.ndarray]
    """Resampled signals, shape [T, ...]; per-joint axes in :attr:`joint_names` order."""
    joint_names: tuple[str, ...] = G1_JOINT_NAMES
    """Joint order of per-joint signals."""

    def __getitem__(self, signal: str) -> np.ndarray:
        """Return a signal, e.g. ``aligned["lowstate.q"]``."""
        return self.signals[signal]

    def __contains__(self, signal: str) -> bool:
        """Whether a signal was resampled."""
        return signal in self.signals

    def joint(self, name: str, signal: str) -> np.ndarray:
        """Return one joint of a per-joint signal, shape [T]."""
        return self.signals[signal][:, joint_index(name)]


def _unique_last(t: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Drop duplicated times, keeping the last sample of each."""
    keep = np.append(np.diff(t) > 0, True)
    return t[keep], v[keep]


def _hold(t_src: np.ndarray, v: np.ndarray, t: np.ndarray, max_age: float) -> np.ndarray:
    """Zero-order hold of ``v`` [N, ...] at ``t`` [T]."""
    idx = np.searchsorted(t_src, t, side="right") - 1
    valid = (idx >= 0) & (t - t_src[np.clip(idx, 0, None)] <= max_age)
    out = v[np.clip(idx, 0, None)].astype(np.float64 if v.dtype != bool else bool)
    if out.dtype == bool:
        return np.where(valid.reshape(-1, *[1] * (v.ndim - 1)), out, False)
    out[~valid] = np.nan
    return out


def _linear(t_src: np.ndarray, v: np.ndarray, t: np.ndarray, max_gap: float) -> np.ndarray:
    """Linear interpolation of ``v`` [N, ...] at ``t`` [T]; NaN outside the span and across gaps."""
    flat = v.reshape(len(v), -1)
    out = np.full((len(t), flat.shape[1]), np.nan)
    inside = (t >= t_src[0]) & (t <= t_src[-1])
    for c in range(flat.shape[1]):
        out[inside, c] = np.interp(t[inside], t_src, flat[:, c])
    nxt = np.clip(np.searchsorted(t_src, t, side="left"), 1, len(t_src) - 1)
    gap = (t_src[nxt] - t_src[nxt - 1]) > max_gap
    out[gap & inside] = np.nan
    return out.reshape(len(t), *v.shape[1:])


def resample(
    t_src: np.ndarray, v: np.ndarray, t: np.ndarray, kind: str, max_gap: float = 0.1, max_age: float = 1.0
) -> np.ndarray:
    """Resample one signal.

    Args:
        t_src: Sample times [s], shape [N], non-decreasing.
        v: Samples, shape [N, ...].
        t: Target times [s], shape [T].
        kind: ``"linear"``, ``"quat"`` (normalized lerp) or ``"hold"``.
        max_gap: Linear/quat interpolation is not done across gaps longer than this [s].
        max_age: Held values older than this become NaN [s].
    """
    t_src, v = _unique_last(np.asarray(t_src, np.float64), np.asarray(v))
    if len(t_src) == 0:
        return np.full((len(t), *v.shape[1:]), np.nan)
    if kind == "hold":
        return _hold(t_src, v, t, max_age)
    if kind == "quat":
        v = v.copy()
        flip = np.cumsum(np.append(0, np.sum(v[1:] * v[:-1], axis=1) < 0)) % 2 == 1
        v[flip] *= -1  # q and -q are the same rotation; interpolate along the short arc
        return quat_normalize(_linear(t_src, v, t, max_gap))
    if len(t_src) == 1:
        return np.where((t == t_src[0])[:, None], v.reshape(1, -1), np.nan).reshape(len(t), *v.shape[1:])
    return _linear(t_src, v.astype(np.float64), t, max_gap)


def _kind(signal: str) -> str:
    """Interpolation kind of a signal."""
    spec, f = signal_spec(signal)
    if spec.interpolation == "linear" and f.unit == "1" and f.shape == (4,):
        return "quat"
    return "hold" if spec.interpolation in ("hold", "none") else "linear"


def align(log: G1Log, cfg: AlignCfg | None = None) -> AlignedLog:
    """Resample a log onto a uniform time base (see module docstring for the rules).

    Args:
        log: Decoded log.
        cfg: Alignment settings.

    Returns:
        The aligned signals; absent optional signals are simply not in :attr:`AlignedLog.signals`.
    """
    cfg = cfg or AlignCfg()
    t_js = (log.channels[TOPIC_JOINT_STATES].time_ns - log.t0_ns) * 1e-9
    rate = cfg.rate_hz or (1.0 / float(np.median(np.diff(t_js))) if len(t_js) > 1 else 1.0)
    t0 = t_js[0] if cfg.t_start is None else cfg.t_start
    t1 = t_js[-1] if cfg.t_end is None else cfg.t_end
    t = t0 + np.arange(int(np.floor((t1 - t0) * rate + 1e-9)) + 1) / rate
    names = cfg.signals if cfg.signals is not None else tuple(log.signals())
    out = {}
    for s in names:
        if not log.has(s):
            continue
        ts, v = log.signal(s)
        out[s] = resample(ts, v, t, _kind(s), cfg.max_gap_s, cfg.hold_max_age_s)
    return AlignedLog(t=t, signals=out, joint_names=log.joint_names)
