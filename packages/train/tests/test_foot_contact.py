# SPDX-License-Identifier: Apache-2.0
"""Gait bookkeeping of FootContactTracker on a hand-made force sequence (no simulator)."""

from __future__ import annotations

import numpy as np
import torch

from gmloco.train.foot_contact import FootContactTracker

DT = 0.02
"""Env step [s] (50 Hz)."""


def _bare_tracker(threshold: float) -> FootContactTracker:
    """A tracker with only the timer state allocated (one env, one foot)."""
    tracker = FootContactTracker.__new__(FootContactTracker)
    tracker.threshold = threshold
    for name in ("force_norm", "air_time", "contact_time", "last_air_time", "landing_force", "height", "swing_peak",
                 "stance_low", "last_swing_apex", "last_swing_lift"):  # fmt: skip
        setattr(tracker, name, torch.zeros(1, 1))
    tracker.in_contact = torch.zeros(1, 1, dtype=torch.bool)
    tracker.first_contact = torch.zeros(1, 1, dtype=torch.bool)
    return tracker


def test_air_time_touchdown_and_landing_force() -> None:
    """|F| = 0, 0, 0, 120, 300, 10 N with a 40 N threshold and 0.02 s steps.

    Steps 1-3 in the air -> air time 0.02, 0.04, 0.06 s. Step 4 touches down: first contact, landing force
    120 N, last swing 0.06 + 0.02 = 0.08 s (the step of the touchdown counts as air), air time reset.
    Step 5 stays down (contact time 0.04 s, no new landing). Step 6 lifts off (10 N < 40 N).
    """
    tracker = _bare_tracker(40.0)
    history = []
    for force in (0.0, 0.0, 0.0, 120.0, 300.0, 10.0):
        tracker.force_norm.fill_(force)
        tracker._update_timers(DT)
        history.append(
            (
                tracker.air_time.item(),
                tracker.contact_time.item(),
                tracker.first_contact.item(),
                tracker.landing_force.item(),
                tracker.last_air_time.item(),
            )
        )
    air, contact, first, landing, last_air = (np.array(c) for c in zip(*history, strict=True))
    np.testing.assert_allclose(air, [0.02, 0.04, 0.06, 0.0, 0.0, 0.02], atol=1e-6)
    np.testing.assert_allclose(contact, [0.0, 0.0, 0.0, 0.02, 0.04, 0.0], atol=1e-6)
    np.testing.assert_array_equal(first, [False, False, False, True, False, False])
    np.testing.assert_allclose(landing, [0.0, 0.0, 0.0, 120.0, 0.0, 0.0])
    np.testing.assert_allclose(last_air[3:], [0.08, 0.08, 0.08], atol=1e-6)


def test_swing_apex_and_lift_out_of_the_footprint() -> None:
    """A foot stands sinking to -5 cm, swings up to +3 cm, lands at -1 cm, sinks to -4 cm, swings to +1 cm, lands.

    First touchdown: apex 3 cm, lift 3 - (-5) = 8 cm. Second: apex 1 cm, lift 1 - (-4) = 5 cm. Between touchdowns
    both values hold; the swing ends at the step that lands (its height counts as stance).
    """
    tracker = _bare_tracker(40.0)
    steps = [  # (|F| [N], sole height [m])
        (300.0, -0.02), (300.0, -0.05), (300.0, -0.04),  # stance, lowest -5 cm
        (0.0, 0.0), (0.0, 0.03), (0.0, 0.01),  # swing, apex 3 cm
        (300.0, -0.01), (300.0, -0.04),  # touchdown, stance to -4 cm
        (0.0, 0.01), (0.0, -0.01),  # swing, apex 1 cm
        (300.0, -0.03),  # touchdown
    ]  # fmt: skip
    apex, lift = [], []
    for force, height in steps:
        tracker.force_norm.fill_(force)
        tracker._update_timers(DT)
        tracker.height.fill_(height)
        tracker._update_swing()
        apex.append(tracker.last_swing_apex.item())
        lift.append(tracker.last_swing_lift.item())
    np.testing.assert_allclose(apex[6:], [0.03, 0.03, 0.03, 0.03, 0.01], atol=1e-7)
    np.testing.assert_allclose(lift[6:], [0.08, 0.08, 0.08, 0.08, 0.05], atol=1e-7)
    # the landing at the first step closes an empty swing (apex and lift 0: the values after a reset)
    np.testing.assert_allclose(apex[:6], 0.0)
