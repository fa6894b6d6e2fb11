# SPDX-License-Identifier: Apache-2.0
"""A bounded memory of simulated shooting segments, keyed by the effect parameters and the segment start.

On the plane and for a welded pelvis every segment is replayed on its own from a reset ``MjData``, so its output
depends on the parameters and its start sample only (``tests/mismatch/test_replay_serial.py``). The fits ask
for some points twice (a pattern-search step that lands on an earlier point, the held-out replay of a fitted
effect, the full replay of the winner), and a replay of a segment subset may follow a replay of all segments;
the memory answers those without stepping the simulator, with the very same bits.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np

__all__ = ["SegmentMemo", "params_key"]


def params_key(params: dict[str, np.ndarray]) -> bytes:
    """Exact key of a parameter dict: effect ids and the bytes of their float64 vectors, in sorted order."""
    return b"".join(k.encode() + b"\0" + np.asarray(v, float).tobytes() for k, v in sorted(params.items()))


class SegmentMemo:
    """Least-recently-used store of segment outputs, each of shape [P, N_CHANNELS]."""

    def __init__(self, max_bytes: int) -> None:
        """Keep at most ``max_bytes`` of segment outputs (0 keeps nothing)."""
        self.max_bytes = max_bytes
        self._store: OrderedDict[tuple[bytes, int], np.ndarray] = OrderedDict()
        self._bytes = 0
        self.hits = 0
        """Segments answered from memory."""

    def get(self, key: bytes, start: int) -> np.ndarray | None:
        """Stored output of segment ``start`` under parameters ``key``, or None."""
        y = self._store.get((key, start))
        if y is not None:
            self._store.move_to_end((key, start))
            self.hits += 1
        return y

    def put(self, key: bytes, start: int, y: np.ndarray) -> None:
        """Store a copy of one segment's output; forget the least recently used beyond ``max_bytes``."""
        if y.nbytes > self.max_bytes or (key, start) in self._store:
            return
        self._store[(key, start)] = y.copy()
        self._bytes += y.nbytes
        while self._bytes > self.max_bytes:
            _, old = self._store.popitem(last=False)
            self._bytes -= old.nbytes
