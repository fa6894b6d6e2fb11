# SPDX-License-Identifier: Apache-2.0
"""Config of the benchmark sweep: which episodes, how many workers, and what is scored."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

__all__ = ["MotionName", "StrengthLevel", "StrengthTableName", "SuiteName", "SweepCfg"]

MotionName = Literal["composite", "turn", "walk", "walk_speeds"]
"""A sand-suite motion (``policy_motion.MOTIONS``)."""
StrengthLevel = Literal["low", "mid", "high"]
"""A strength level of the plane suite (``episodes.STRENGTHS``)."""
StrengthTableName = Literal["v3", "v4"]
"""A mid-strength table (``episodes.STRENGTH_TABLES``)."""
SuiteName = Literal["plane", "sand"]
"""A benchmark suite: ``plane`` (scripted stepping) or ``sand`` (the policy walking on sand)."""


@dataclass(frozen=True)
class SweepCfg:
    """One sweep invocation: the episode list, its selection, the workers and the scoring."""

    workers: int = field(default=2, metadata={"ge": 1})
    """Worker processes, one episode each at a time."""
    seeds: int = field(default=1, metadata={"ge": 0})
    """Seeds per (effect, strength) episode."""
    nulls: int = field(default=20, metadata={"ge": 0})
    """Episodes without a hidden effect."""
    duration: float | None = field(default=None, metadata={"gt": 0})
    """Recording length [s]; None: 8 on the plane, the motion's length on sand (walk 8, composite 18)."""
    motion: MotionName = "walk"
    """Sand suite's policy command schedule (walk: 1 m/s; composite: stand, 0.5/1.0/1.5 m/s, a turn)."""
    strengths: tuple[StrengthLevel, ...] = ("mid",)
    """Plane suite's strength levels of the hidden effects."""
    strength_table: StrengthTableName = "v3"
    """Mid-strength table (v3: the stock strengths; v4: every mid strength >= 1.5x the effect's tolerance)."""
    suite: SuiteName = "plane"
    """Benchmark suite (plane: scripted stepping; sand: the policy)."""
    keep_before_fall: float | None = field(default=None, metadata={"ge": 0})
    """Trim a truth log that ends in a fall to this many seconds before it [s]; None: the episode errors."""
    only: tuple[str, ...] | None = None
    """Episode-name prefixes to run; None: every episode of the list."""
    score_only: bool = False
    """Score the rows already under ``OUT/rows`` and exit."""
    pool: str | None = None
    """With ``score_only``: a second sweep folder (another suite) whose rows are scored pooled with ``OUT/rows``
    into ``OUT/summary_pooled.json``."""
    resume: bool = False
    """Skip episodes whose row already exists under ``OUT/rows``."""
    effects: tuple[str, ...] | None = None
    """Effect ids the tool screens; None: all."""
    seed_offset: int = 0
    """Added to every episode's seed (fresh test seeds; the names are unchanged)."""
    part: str | None = None
    """``I/N``: run only the episodes at positions I, I+N, ... of the list; None: all."""
    deadline_s: float | None = None
    """Start no episode later than this many seconds after the sweep began (the rest: ``resume`` later) [s]."""
