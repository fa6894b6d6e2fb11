# SPDX-License-Identifier: Apache-2.0
"""The segment memory answers repeated replays with the bits of a fresh replay, within its byte budget."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from gmloco.deploy.mismatch.memo import SegmentMemo, params_key
from gmloco.deploy.mismatch.recording import Recording
from gmloco.deploy.mismatch.replay import ReplayCfg, Replayer


def test_remembered_segments_equal_a_fresh_replay(null_rec: Recording) -> None:
    """Full replay, then a subset and an overlapping set: every answer equals a replayer without memory."""
    params = {"actuator.backlash": np.array([0.01, 0.02, 0.0]), "joint.armature": np.array([0.3])}
    with_memo, without = Replayer(null_rec), Replayer(null_rec, replace(ReplayCfg(), memo_bytes=0))
    starts = with_memo.segment_starts()[:9]
    full = with_memo.simulate(params, starts)
    assert with_memo._memo.hits == 0
    np.testing.assert_array_equal(full, without.simulate(params, starts))
    subset = starts[::2]
    np.testing.assert_array_equal(with_memo.simulate(params, subset), without.simulate(params, subset))
    assert with_memo._memo.hits == len(subset)
    mixed = with_memo.segment_starts()[5:12]  # four remembered, three new
    np.testing.assert_array_equal(with_memo.simulate(params, mixed), without.simulate(params, mixed))
    assert with_memo._memo.hits == len(subset) + 4


def test_other_parameters_are_never_answered_from_memory(null_rec: Recording) -> None:
    """A parameter change of one ulp is another key: the memory never mixes parameter sets."""
    rp = Replayer(null_rec)
    starts = rp.segment_starts()[:3]
    a = {"joint.viscous_damping": np.array([0.5])}
    b = {"joint.viscous_damping": np.array([np.nextafter(0.5, 1.0)])}
    assert params_key(a) != params_key(b)
    rp.simulate(a, starts)
    rp.simulate(b, starts)
    assert rp._memo.hits == 0


def test_memory_stays_within_its_byte_budget() -> None:
    """Least recently used segments go first once the budget is spent; a zero budget keeps nothing."""
    y = np.zeros((10, 96))  # 7680 bytes, one segment's output
    memo = SegmentMemo(max_bytes=2 * y.nbytes)
    for k0 in range(3):
        memo.put(b"p", k0, y + k0)
    assert memo.get(b"p", 0) is None
    np.testing.assert_array_equal(memo.get(b"p", 2), y + 2)
    memo.put(b"p", 3, y)  # 1 is now the least recently used
    assert memo.get(b"p", 1) is None and memo.get(b"p", 2) is not None
    empty = SegmentMemo(max_bytes=0)
    empty.put(b"p", 0, y)
    assert empty.get(b"p", 0) is None
