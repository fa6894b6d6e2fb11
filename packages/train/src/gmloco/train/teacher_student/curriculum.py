# SPDX-License-Identifier: Apache-2.0
"""Curriculum on the student's loss weights w_PPO and w_dist (Kamohara et al., arXiv 2603.13707, Sec. IV-B).

The paper anneals from imitation to reinforcement: the student first clones the teacher (w_dist high, w_PPO low),
then PPO takes over so the student can improve where imitation alone is not enough. The shape and length of the
schedule are not given; we use a linear ramp between two update counts.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["LinearRamp"]


@dataclass(frozen=True)
class LinearRamp:
    """A weight that moves linearly from ``start`` to ``end`` between two update counts, constant outside."""

    start: float
    """Weight up to update ``begin``."""
    end: float
    """Weight from update ``finish`` on."""
    begin: int = 0
    """Update count at which the ramp starts."""
    finish: int = 1000
    """Update count at which the ramp ends (``finish <= begin``: a step at ``begin``)."""

    def __call__(self, update: int) -> float:
        """Return the weight at learning update ``update`` (0-based)."""
        if update <= self.begin:
            return self.start
        if update >= self.finish:
            return self.end
        frac = (update - self.begin) / (self.finish - self.begin)
        return self.start + frac * (self.end - self.start)
