# SPDX-License-Identifier: Apache-2.0
"""Config of one run of a pre-registered benchmark (v5, v6): which suite, which episodes, how many workers."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

__all__ = ["ProtocolRunCfg", "Suite"]

Suite = Literal["fixed", "plane", "sand", "identification"]
"""A suite: v5's ``fixed`` (gantry chirps), ``plane`` (scripted stepping) and ``sand`` (the policy walking on
sand); v6's ``identification`` (one robot on the gantry and stepping on the plane, one diagnosis)."""


@dataclass(frozen=True)
class ProtocolRunCfg:
    """One run of a protocol: a suite, the selection of its pre-registered episodes, the workers and the scoring."""

    suite: Suite = "fixed"
    """Suite whose episodes run (rows under ``OUT/<suite>/rows``); it must be one of the protocol's."""
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
