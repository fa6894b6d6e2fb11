# SPDX-License-Identifier: Apache-2.0
"""Jump metrics from a recorded trace: landing success, height and distance vs the reference, slip, sinkage.

Pure numpy functions over a :class:`JumpTrace` (what :func:`gmloco.train.tasks.g1_jump.evaluation.rollout_jump`
records in the training simulator, or any simulator that fills the same arrays).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

__all__ = [
    "FAILURE_MIN_BASE_HEIGHT",
    "FAILURE_TILT",
    "FLIGHT_CLEARANCE",
    "JumpMetrics",
    "JumpTrace",
    "airborne",
    "detect_flight",
    "jump_metrics",
]

FAILURE_TILT = np.radians(70.0)
"""Pelvis tilt from upright that counts as a fall [rad] (the walk task's ``fell_over`` termination)."""
FAILURE_MIN_BASE_HEIGHT = 0.3
"""Pelvis height above the sand surface below which the robot has fallen [m] (``base_too_low``)."""
FLIGHT_CLEARANCE = 0.01
"""Height of both soles above the free surface (beyond their flat-foot height) that counts as flight [m]; a
contact force below the threshold alone is not enough on sand, where an unloading foot reads as off."""


@dataclass
class JumpTrace:
    """One attempt, T samples at ``1 / dt``; positions relative to the attempt's start origin, world axes."""

    dt: float
    """Sample period [s]."""
    base_pos: np.ndarray
    """Pelvis position [m], shape [T, 3]."""
    base_height: np.ndarray
    """Pelvis height above the sand free surface [m], shape [T]."""
    tilt: np.ndarray
    """Angle between the pelvis z axis and the world z axis [rad], shape [T]."""
    feet_pos: np.ndarray
    """Sole-site positions, left then right [m], shape [T, 2, 3]."""
    foot_height: np.ndarray
    """Sole-site height above the sand free surface [m] (negative: sunk), shape [T, 2]."""
    in_contact: np.ndarray
    """Foot contact (force above the task's threshold), shape [T, 2] (bool)."""
    ref_base_pos: np.ndarray
    """Reference pelvis position at the sample times of the whole attempt [m], shape [T_ref, 3] (T_ref >= T: a
    trace cut short by a fall keeps the full reference)."""
    push_start_s: float
    """Reference start of the push-off [s] (slip is measured from here to take-off)."""
    sole_height: float
    """Sole-site height above the ground of a foot standing flat on rigid ground [m]."""


@dataclass
class JumpMetrics:
    """Scores of one attempt (SI units unless the name says cm or pct)."""

    landing_success: bool
    """A take-off and a touch-down happened and no failure rule fired up to 1 s after the touch-down."""
    takeoff_s: float
    """First airborne time (:func:`airborne`) after the push-off start [s] (nan: no flight)."""
    touchdown_s: float
    """First contact after the take-off [s] (nan: no landing)."""
    height: float
    """Highest pelvis height in flight minus the starting pelvis height [m]."""
    ref_height: float
    """The same for the reference [m]."""
    height_error_pct: float
    """100 |height - ref_height| / ref_height (nan for a reference that does not rise)."""
    distance: float
    """Forward pelvis travel from start to the end of the trace [m]."""
    ref_distance: float
    """The same for the reference [m]."""
    takeoff_slip_cm: float
    """Largest horizontal sole displacement between the push-off start and the take-off [cm] (nan: no take-off)."""
    sinkage_cm: float
    """Deepest sole sinkage below the free surface, over the whole attempt [cm] (0 on rigid ground)."""

    def to_dict(self) -> dict[str, float | bool]:
        """Plain-dict form (JSON-ready)."""
        return asdict(self)


def airborne(trace: JumpTrace) -> np.ndarray:
    """Samples with no foot in contact and both soles ``FLIGHT_CLEARANCE`` above the surface, shape [T] (bool)."""
    clear = np.all(trace.foot_height > trace.sole_height + FLIGHT_CLEARANCE, axis=-1)
    return ~np.any(trace.in_contact, axis=-1) & clear


def detect_flight(flying: np.ndarray, start: int = 0) -> tuple[int | None, int | None]:
    """Return the first sample at or after ``start`` that is airborne, and the next one that is not."""
    off = np.flatnonzero(flying[start:])
    if off.size == 0:
        return None, None
    takeoff = start + int(off[0])
    on = np.flatnonzero(~flying[takeoff:])
    return takeoff, (takeoff + int(on[0]) if on.size else None)


def _failed(trace: JumpTrace) -> np.ndarray:
    """Per-sample failure rule of the training env: tilt above 70 deg or pelvis below 0.3 m, shape [T]."""
    return (trace.tilt > FAILURE_TILT) | (trace.base_height < FAILURE_MIN_BASE_HEIGHT)


def _landing_success(trace: JumpTrace, takeoff: int | None, touchdown: int | None, hold_s: float) -> bool:
    """Take-off, touch-down, then ``hold_s`` [s] of trace with no failure (a trace cut short by a fall fails)."""
    if takeoff is None or touchdown is None:
        return False
    end = touchdown + round(hold_s / trace.dt)
    if end >= trace.base_pos.shape[0]:
        return False
    return not bool(_failed(trace)[: end + 1].any())


def jump_metrics(trace: JumpTrace, hold_s: float = 1.0) -> JumpMetrics:
    """Score one attempt; flight is searched from the push-off start on (earlier hops do not count)."""
    start = int(np.ceil(trace.push_start_s / trace.dt))
    takeoff, touchdown = detect_flight(airborne(trace), start)
    z0, ref_z0 = trace.base_pos[0, 2], trace.ref_base_pos[0, 2]
    ref_height = float(trace.ref_base_pos[:, 2].max() - ref_z0)
    height = float(trace.base_pos[takeoff:touchdown, 2].max() - z0) if takeoff is not None else 0.0
    slip = float("nan")
    if takeoff is not None:
        last = max(takeoff - 1, start)  # last stance sample
        slip = float(np.linalg.norm(trace.feet_pos[last, :, :2] - trace.feet_pos[start, :, :2], axis=-1).max())
    sink = max(0.0, float(-(trace.foot_height - trace.sole_height).min()))
    nan = float("nan")
    return JumpMetrics(
        landing_success=_landing_success(trace, takeoff, touchdown, hold_s),
        takeoff_s=nan if takeoff is None else takeoff * trace.dt,
        touchdown_s=nan if touchdown is None else touchdown * trace.dt,
        height=height,
        ref_height=ref_height,
        height_error_pct=100.0 * abs(height - ref_height) / ref_height if ref_height > 0.0 else nan,
        distance=float(trace.base_pos[-1, 0] - trace.base_pos[0, 0]),
        ref_distance=float(trace.ref_base_pos[-1, 0] - trace.ref_base_pos[0, 0]),
        takeoff_slip_cm=100.0 * slip,
        sinkage_cm=100.0 * sink,
    )
