# SPDX-License-Identifier: Apache-2.0
"""Config of one benchmark-v5 invocation: which suite, which of its episodes, how many workers, what is scored."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

__all__ = ["V5RunCfg", "V5Suite"]

V5Suite = Literal["fixed", "plane", "sand"]
"""A v5 suite: ``fixed`` (gantry chirps), ``plane`` (scripted stepping), ``sand`` (the policy walking on sand)."""


@dataclass(frozen=True)
class V5RunCfg:
    """One v5 run: a suite, the selection of its pre-registered episodes, the workers and the scoring."""

    suite: V5Suite = "fixed"
    """Suite whose episodes run (rows under ``OUT/<suite>/rows``)."""
    workers: int = field(default=2, metadata={"ge": 1})
    """Worker processes, one episode each at a time."""
    part: str | None = None
    """``I/N``: run only the episodes at positions I, I+N, ... of the suite's list; None: all."""
    only: tuple[str, ...] | None = None
    """Episode-name prefixes to run; None: every episode of the selection."""
    resume: bool = False
    """Skip episodes whose row already exists."""
    deadline_s: float | None = field(default=None, metadata={"gt": 0})
    """Start no episode later than this many seconds after the run began (the rest: ``resume`` later) [s]."""
    list_episodes: bool = False
    """Print the suite's episodes (name and seed) and exit."""
    score_only: bool = False
    """Score the rows already written (the suite and the pool) and exit."""
