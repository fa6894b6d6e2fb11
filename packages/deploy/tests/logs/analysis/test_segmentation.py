# SPDX-License-Identifier: Apache-2.0
"""Stance/swing segmentation on a synthetic gait with known stance windows."""

from __future__ import annotations

import numpy as np

from gmloco.deploy.logs.analysis import SegmentationCfg, phase_windows, segment_stance


def _gait(dt: float = 0.001) -> tuple[np.ndarray, np.ndarray, list[tuple[float, float]]]:
    """Alternating half-sine swings of 0.3 s, 5 cm apex, period 0.8 s; stance foot at height 0.

    Returns time, sole heights [T, 2] (offset by a common -0.7 m, which must cancel), and left swing windows.
    """
    t = np.arange(0, 4.0, dt)
    h = np.zeros((len(t), 2))
    swings = []
    for k, offset in enumerate((0.2, 0.6)):
        for start in np.arange(offset, 3.6, 0.8):
            m = (t >= start) & (t < start + 0.3)
            h[m, k] = 0.05 * np.sin(np.pi * (t[m] - start) / 0.3)
            if k == 0:
                swings.append((start, start + 0.3))
    return t, h - 0.7, swings


def test_segmentation_recovers_known_stance_windows() -> None:
    """Lift-off and touchdown times equal the hand-computed threshold crossings.

    Swing height h(s) = A sin(pi s / T), A = 0.05 m, T = 0.3 s. Lift-off is declared at h = 0.02 m:
    s_lo = T/pi * asin(0.4) = 0.0393 s after swing start; touchdown at h = 0.01 m on the way down:
    s_td = T - T/pi * asin(0.2) = 0.2808 s after swing start.
    """
    t, h, swings = _gait()
    cfg = SegmentationCfg(touchdown_height=0.01, liftoff_height=0.02, min_phase_s=0.05)
    stance = segment_stance(t, h, cfg)
    windows = phase_windows(stance[:, 0], value=False)
    s_lo = 0.3 / np.pi * np.arcsin(0.02 / 0.05)
    s_td = 0.3 - 0.3 / np.pi * np.arcsin(0.01 / 0.05)
    assert len(windows) == len(swings)
    for (a, b), (start, _) in zip(windows, swings, strict=True):
        np.testing.assert_allclose(t[a], start + s_lo, atol=1.5e-3)  # one sample (1 ms) of quantization
        np.testing.assert_allclose(t[b], start + s_td, atol=1.5e-3)


def test_debounce_removes_short_blips() -> None:
    """A 10 ms spike of a stance foot (sensor glitch) does not split the stance."""
    t, h, _ = _gait()
    h[1000:1010, 1] += 0.03  # right foot is in stance at t = 1.0 s
    stance = segment_stance(t, h, SegmentationCfg(min_phase_s=0.05))
    assert stance[1000:1010, 1].all()


def test_double_stance_when_standing() -> None:
    """Both feet at the same height: both in stance."""
    t = np.arange(0, 1, 0.01)
    assert segment_stance(t, np.zeros((len(t), 2))).all()
