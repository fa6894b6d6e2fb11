# SPDX-License-Identifier: Apache-2.0
"""Signal-group balancing of the residual and the block-bootstrap held-out bound (no simulation)."""

from __future__ import annotations

import numpy as np

from gmloco.deploy.mismatch.attribution import _boot_p
from gmloco.deploy.mismatch.problem import group_balance


def test_group_balance_gives_each_group_equal_weight() -> None:
    """Every active group gets total weight N / G; the total null energy stays N; inactive columns stay 0."""
    act = np.ones(96)
    w = group_balance(act) ** 2
    assert np.isclose(w.sum(), 96.0)
    for o, n in ((0, 29), (29, 29), (58, 29), (87, 3), (90, 3), (93, 3)):
        assert np.isclose(w[o : o + n].sum(), 96.0 / 6)
    act[58:87] = 0.0  # no torque estimates logged: 67 active columns in 5 groups
    w = group_balance(act) ** 2 * act
    assert np.isclose(w.sum(), 67.0) and np.all(w[58:87] == 0.0)
    assert np.isclose(w[87:90].sum(), 67.0 / 5)


def test_bootstrap_gain_bound_is_below_the_weakest_block() -> None:
    """The lower bound of the held-out gain cannot exceed the gain of the worst held-out block."""
    blocks = np.repeat([2, 5], 10)
    e0 = np.ones(20)
    e1 = np.r_[np.full(10, 0.6), np.full(10, 0.9)]  # block gains 0.4 and 0.1
    p, lo = _boot_p(e0, e1, blocks, 400, np.random.default_rng(0))
    assert p < 0.01
    assert lo <= 0.1 + 1e-9
