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
    for name in ("force_norm", "air_time", "contact_time", "last_air_time", "landing_force"):
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
