# SPDX-License-Identifier: Apache-2.0
"""Scripted joint chirps for fixed-base recordings: the in-air identification stage (S1) of the reference design.

With the pelvis held (a gantry or a stand), every leg and waist joint follows an exponential chirp about the
knees-bent pose, PD-tracked by the motor drivers (``shared/reference/mismatch-discovery.md`` section 3.3, stage S1:
delay, armature, friction, gains). Each joint gets its own phase offset so that no two joints move in lockstep,
and the amplitude falls as ``(f_knee / f)^0.5`` above ``f_knee`` so joint speeds stay moderate while accelerations
still grow with frequency. Arms hold the pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gmloco.deploy.logs.g1 import G1_JOINT_NAMES
from gmloco.deploy.mismatch.benchmark.controller import default_pose

__all__ = ["ChirpCfg", "ChirpMotion", "chirp_amplitudes"]


@dataclass
class ChirpCfg:
    """An exponential joint chirp on a held pelvis."""

    f_start: float = 0.5
    """Start frequency [Hz]."""
    f_end: float = 6.0
    """End frequency, reached at ``duration`` [Hz]."""
    duration: float = 2.0
    """Sweep length [s]; the sweep then starts again from ``f_start``, phase-continuous, so every stretch of a
    long recording (and every held-out block of the analysis) sees high frequencies."""
    amplitude: float = 0.15
    """Hip, knee and ankle-pitch amplitude below ``f_knee`` [rad]; ankle roll and waist get ``small_amplitude``."""
    small_amplitude: float = 0.08
    """Amplitude of the joints with narrow ranges (ankle roll, waist roll and pitch, hip roll) [rad]."""
    f_knee: float = 1.5
    """Frequency above which the amplitude falls as ``(f_knee / f)^0.5`` [Hz]."""
    ramp: float = 0.2
    """Amplitude ramp-in at the start [s]."""


def chirp_amplitudes(cfg: ChirpCfg) -> np.ndarray:
    """Low-frequency amplitude per joint [rad], shape [29] (zero for arms)."""
    amp = np.zeros(29)
    for i, n in enumerate(G1_JOINT_NAMES):
        if any(k in n for k in ("ankle_roll", "hip_roll", "waist_roll", "waist_pitch")):
            amp[i] = cfg.small_amplitude
        elif any(k in n for k in ("hip", "knee", "ankle", "waist")):
            amp[i] = cfg.amplitude
    return amp


class ChirpMotion:
    """Joint targets of a fixed-base chirp (same call signature as the scripted gaits)."""

    def __init__(self, cfg: ChirpCfg) -> None:
        """Set the pose, the amplitudes and the per-joint phase offsets."""
        self.cfg = cfg
        self.q0 = default_pose()
        self.amp = chirp_amplitudes(cfg)
        self.offset = 2.0 * np.pi * ((np.arange(29) * 0.6180339887) % 1.0)  # golden-ratio spread of phases

    def frequency(self, t: float) -> float:
        """Instantaneous sweep frequency [Hz] at time ``t`` [s]."""
        c = self.cfg
        return c.f_start * (c.f_end / c.f_start) ** ((t % c.duration) / c.duration)

    def _phase(self, t: float) -> float:
        """Sweep phase [rad]: the integral of ``2 pi f`` over the completed sweeps and the current one."""
        c = self.cfg
        k = np.log(c.f_end / c.f_start) / c.duration
        sweeps, ts = divmod(t, c.duration)
        per_sweep = c.f_start * np.expm1(k * c.duration) / k
        return 2.0 * np.pi * (sweeps * per_sweep + c.f_start * np.expm1(k * ts) / k)

    def targets(self, t: float, quat: np.ndarray, gyro: np.ndarray) -> np.ndarray:
        """Return joint position targets [rad], shape [29] (the IMU arguments are not used)."""
        c = self.cfg
        scale = min(1.0, t / c.ramp) if c.ramp > 0 else 1.0
        scale *= min(1.0, (c.f_knee / self.frequency(t)) ** 0.5)
        return self.q0 + scale * self.amp * np.sin(self._phase(t) + self.offset)
