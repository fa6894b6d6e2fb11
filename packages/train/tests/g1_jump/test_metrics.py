# SPDX-License-Identifier: Apache-2.0
"""Jump metrics on hand-built traces: flight detection, height, distance, slip, sinkage, landing success."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from gmloco.train.tasks.g1_jump.metrics import JumpTrace, airborne, detect_flight, jump_metrics

DT = 0.02
"""Sample period of the traces [s] (the policy rate)."""
SOLE = 0.002
"""Sole-site height over a flat foot [m]."""


def _trace(n: int = 150, takeoff: int = 50, touchdown: int = 65) -> JumpTrace:
    """Stand at z = 0.75 m, a 10 cm base rise in flight (samples [takeoff, touchdown)), feet 2 cm into sand."""
    base = np.zeros((n, 3))
    base[:, 2] = 0.75
    flight = np.arange(takeoff, touchdown)
    base[flight, 2] += 0.10 * np.sin(np.pi * (flight - takeoff + 0.5) / (touchdown - takeoff))
    base[:, 0] = np.linspace(0.0, 0.3, n)
    contact = np.ones((n, 2), dtype=bool)
    contact[takeoff:touchdown] = False
    feet = np.zeros((n, 2, 3))
    feet[:, 1, 1] = -0.24
    feet[:takeoff, 0, 0] = np.linspace(0.0, 0.03, takeoff)  # left sole slides 3 cm during the push
    height = np.full((n, 2), SOLE - 0.02)
    height[takeoff:touchdown] = 0.05
    ref = base.copy()
    ref_flight = np.arange(50, 65)
    ref[:, 2] = 0.75
    ref[ref_flight, 2] += 0.125 * np.sin(np.pi * (ref_flight - 50 + 0.5) / 15)  # the reference rises 12.5 cm
    return JumpTrace(
        dt=DT,
        base_pos=base,
        base_height=base[:, 2],
        tilt=np.zeros(n),
        feet_pos=feet,
        foot_height=height,
        in_contact=contact,
        ref_base_pos=ref,
        push_start_s=0.0,
        sole_height=SOLE,
    )


def test_detect_flight_finds_take_off_and_touch_down() -> None:
    """Airborne from sample 3 to 5: take-off 3, touch-down 6; never airborne: neither."""
    flying = np.array([0, 0, 0, 1, 1, 1, 0, 0], dtype=bool)
    assert detect_flight(flying) == (3, 6)
    assert detect_flight(np.zeros(5, dtype=bool)) == (None, None)
    assert detect_flight(flying[:6]) == (3, None)
    assert detect_flight(flying, start=4) == (4, 6)


def test_unloaded_feet_on_the_surface_are_not_flight() -> None:
    """No contact force but soles still in the sand (an unloading foot on sand) is not airborne."""
    trace = _trace()
    sunk = replace(trace, foot_height=np.full_like(trace.foot_height, SOLE - 0.02))
    assert airborne(trace)[55] and not airborne(sunk).any()
    assert not jump_metrics(sunk).landing_success


def test_metrics_of_a_clean_jump() -> None:
    """Height 10 cm vs 12.5 cm (20 % short), 0.3 m travelled, 3 cm slip, 2 cm sinkage, success."""
    m = jump_metrics(_trace())
    assert m.landing_success
    assert m.takeoff_s == pytest.approx(50 * DT) and m.touchdown_s == pytest.approx(65 * DT)
    # sin peaks at 0.1 * sin(pi * 7.5 / 15) = 0.1 exactly at the middle sample
    assert m.height == pytest.approx(0.10, abs=1e-12)
    assert m.ref_height == pytest.approx(0.125, abs=1e-12)
    assert m.height_error_pct == pytest.approx(20.0)
    assert m.distance == pytest.approx(0.3) and m.ref_distance == pytest.approx(0.3)
    assert m.takeoff_slip_cm == pytest.approx(3.0)
    assert m.sinkage_cm == pytest.approx(2.0)


def test_fall_after_landing_fails() -> None:
    """A tilt over 70 deg within 1 s of the touch-down fails the landing."""
    trace = _trace()
    tilt = trace.tilt.copy()
    tilt[65 + 30] = np.radians(80.0)
    assert not jump_metrics(replace(trace, tilt=tilt)).landing_success


def test_trace_ending_before_one_second_after_landing_fails() -> None:
    """A trace cut 0.5 s after the touch-down (the env reset on a failure) is no success."""
    t = _trace(n=90)
    assert not jump_metrics(t).landing_success


def test_no_flight_scores_zero_height() -> None:
    """A robot that never leaves the ground has no take-off, height 0 and a 100 % height error."""
    m = jump_metrics(_trace(takeoff=150, touchdown=150))
    assert not m.landing_success and np.isnan(m.takeoff_s) and np.isnan(m.takeoff_slip_cm)
    assert m.height == 0.0 and m.height_error_pct == pytest.approx(100.0)
