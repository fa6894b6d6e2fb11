# SPDX-License-Identifier: Apache-2.0
"""The ``foot_clearance="sinkage"`` swing terms on synthetic foot trajectories (no simulator).

A foot stands sunk s below the free surface, swings on h(t) = -s + (a + s) sin(pi t / T) at 1 m/s, and lands back
at -s, three times. The swing bookkeeping is :class:`~gmloco.train.foot_contact.FootContactTracker`'s own; the
terms and weights are those ``make_rewards_cfg`` builds for the mode. The apex a that earns the most is the apex the
terms ask for.
"""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
import torch

from gmloco.train.foot_contact import FootContactTracker
from gmloco.train.mdp.rewards import _sinkage_lift_paid, sinkage_clearance_target

DT = 0.02
"""Policy step [s]."""
STIFF, SOFT = 0.005, 0.07
"""Footprint depths [m]: basalt-like, and poppy seed's (lift minus apex of the td student, ~7 cm)."""
APEXES = np.round(np.arange(0.0, 0.301, 0.005), 3)
"""Swing apexes tried [m]."""


def _terms(mode: str, l2_weight: float) -> dict[str, Any]:
    """The swing terms of the mode as the task builds them, with the L2 penalty's weight replaced."""
    from gmloco.train import g1_granular_task
    from gmloco.train.tasks.g1_granular.rewards_cfg import make_rewards_cfg

    task = replace(g1_granular_task("rft3d"), foot_clearance=mode)  # type: ignore[arg-type]
    terms = {k: v for k, v in make_rewards_cfg(task).items() if k in ("foot_clearance_l2", "swing_height_at_touchdown")}
    terms["foot_clearance_l2"] = replace(terms["foot_clearance_l2"], weight=l2_weight)
    return terms


def _tracker() -> Any:
    """A one-env, one-foot tracker whose contact and kinematics the test sets by hand."""
    tracker = object.__new__(FootContactTracker)
    for name in ("height", "swing_peak", "stance_low", "last_swing_apex", "last_swing_lift"):
        setattr(tracker, name, torch.zeros(1, 1))
    tracker.in_contact = torch.zeros(1, 1, dtype=torch.bool)
    tracker.first_contact = torch.zeros(1, 1, dtype=torch.bool)
    tracker.vel_w = torch.zeros(1, 1, 3)
    tracker.update = lambda: tracker
    return tracker


def _trajectory(sinkage: float, apex: float, cycles: int = 3, stance: int = 10, swing: int = 20) -> list[tuple]:
    """(height [m], in contact, speed [m/s]) per step of ``cycles`` stance + swing cycles."""
    steps: list[tuple] = []
    for _ in range(cycles):
        steps += [(-sinkage, True, 0.0)] * stance
        steps += [(-sinkage + (apex + sinkage) * np.sin(np.pi * t / swing), False, 1.0) for t in range(1, swing)]
    return [*steps, (-sinkage, True, 0.0)]


def _return(terms: dict[str, Any], sinkage: float, apex: float) -> float:
    """Weighted sum of the terms over the trajectory (reward per step times dt, as mjlab's reward manager)."""
    feet = _tracker()
    commands = torch.tensor([[1.0, 0.0, 0.0]])
    env = SimpleNamespace(
        sand=SimpleNamespace(feet=feet), command_manager=SimpleNamespace(get_command=lambda n: commands)
    )
    total = 0.0
    for height, contact, speed in _trajectory(sinkage, apex):
        feet.first_contact.fill_(contact and not bool(feet.in_contact))
        feet.in_contact.fill_(contact)
        feet.height.fill_(height)
        feet.vel_w[..., 0] = speed
        feet._update_swing()
        total += sum(float(t.func(env, **t.params).sum()) * t.weight * DT for t in terms.values())
    return total


def _best_apex(terms: dict[str, Any], sinkage: float) -> float:
    """The apex [m] of :data:`APEXES` with the highest return."""
    return float(APEXES[int(np.argmax([_return(terms, sinkage, a) for a in APEXES]))])


def test_target_grows_with_sinkage_and_saturates() -> None:
    """min(0.09 + 1.0 max(s, 0), 0.20): 9 cm stiff (and for a foot above the surface), 16 cm at 7 cm, 20 cm cap."""
    s = torch.tensor([-0.02, 0.0, 0.07, 0.5])
    np.testing.assert_allclose(
        sinkage_clearance_target(s, 0.09, 1.0, 0.20).numpy(), [0.09, 0.09, 0.16, 0.20], atol=1e-7
    )


def test_touchdown_pay_reaches_the_target_apex() -> None:
    """Footprint 7 cm (lift - apex): pay grows until the apex is 16 cm (lift 23 cm), then stays; stiff: 9 cm."""
    apex = torch.tensor([0.05, 0.16, 0.25, 0.09, 0.12])
    lift = apex + torch.tensor([0.07, 0.07, 0.07, 0.0, 0.0])
    paid = _sinkage_lift_paid(apex, lift, 0.09, 1.0, 0.20)
    np.testing.assert_allclose(paid.numpy(), [0.12, 0.23, 0.23, 0.09, 0.09], atol=1e-6)


@pytest.mark.parametrize("l2_weight", [-2.0, -50.0])
def test_sinkage_mode_pays_a_higher_apex_on_soft_sand(l2_weight: float) -> None:
    """Sinkage mode: the best apex rises >= 5 cm from a 0.5 cm to a 7 cm footprint; touchdown mode: it does not.

    Weights: the task's (-2, +100) and the committed runs' override of the penalty (-50).
    """
    sinkage = _terms("sinkage", l2_weight)
    rise = _best_apex(sinkage, SOFT) - _best_apex(sinkage, STIFF)
    touchdown = _terms("touchdown", l2_weight)
    rise_today = _best_apex(touchdown, SOFT) - _best_apex(touchdown, STIFF)
    assert rise >= 0.05, (rise, rise_today)
    assert rise_today < 0.02, (rise, rise_today)


def test_sinkage_mode_leaves_other_modes_unchanged() -> None:
    """Penalty and touchdown modes build today's functions and parameters; only "sinkage" uses the new terms."""
    from gmloco.train import g1_granular_task, mdp
    from gmloco.train.tasks.g1_granular.rewards_cfg import make_rewards_cfg

    task = g1_granular_task("rft3d")
    for mode in ("penalty", "touchdown"):
        terms = make_rewards_cfg(replace(task, foot_clearance=mode))  # type: ignore[arg-type]
        assert terms["foot_clearance_l2"].func is mdp.foot_clearance_l2
        assert terms["foot_clearance_l2"].params == {"target_height": 0.10, "tanh_mult": 2.0}
    assert make_rewards_cfg(replace(task, foot_clearance="touchdown"))["swing_height_at_touchdown"].params == {
        "target_height": 0.12, "command_name": "twist", "relative": True,
    }  # fmt: skip
    terms = make_rewards_cfg(replace(task, foot_clearance="sinkage"))
    assert terms["foot_clearance_l2"].func is mdp.foot_clearance_sinkage_l2
    assert terms["swing_height_at_touchdown"].func is mdp.swing_apex_sinkage_at_touchdown
    assert (terms["foot_clearance_l2"].weight, terms["swing_height_at_touchdown"].weight) == (-2.0, 100.0)
    assert g1_granular_task("rft3d").foot_clearance == "penalty"
