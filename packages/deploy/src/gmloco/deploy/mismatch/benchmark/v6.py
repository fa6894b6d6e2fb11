# SPDX-License-Identifier: Apache-2.0
"""Benchmark v6: one robot recorded in the identification stages and diagnosed once, pre-registered.

The protocol is ``results/mismatch_benchmark/v6/protocol.md``; this module is its runner. Usage::

    python -m gmloco.deploy.mismatch.benchmark.v6 --out results/mismatch_benchmark/v6 --suite identification
        [--workers N] [--part I/N] [--resume] [--deadline-s S] [--list] [--score-only]

Each ``identification`` episode records one robot (one seed: its concealed effect, nuisances and noise) twice,
hanging on the gantry under joint chirps and stepping in place on the plane, and hands both recordings to one
diagnosis (``gmloco-mismatch --real chirp.mcap --real step.mcap``). The classes are v5's plane table (every
library class that can act on the robot on a plane or a gantry), two seeds each, the two out-of-library classes
and ``NULLS_PER_SUITE`` nulls, on fresh seeds (``SEED_BASE``). The pool adds v5's sand suite as scored there
(the sand ground is not an identification stage): ``OUT/summary_pooled.json``.
"""

from __future__ import annotations

from pathlib import Path

from gmloco.deploy.mismatch.benchmark import protocol
from gmloco.deploy.mismatch.benchmark.episodes import MID, OOL
from gmloco.deploy.mismatch.benchmark.protocol import FLAGS, TARGETS, Protocol
from gmloco.deploy.mismatch.benchmark.protocol_cfg import ProtocolRunCfg
from gmloco.deploy.mismatch.benchmark.v5 import NEW_MID_V5

__all__ = ["FLAGS", "NULLS_PER_SUITE", "SEED_BASE", "STAGES", "SUITES", "TARGETS", "V6", "main", "suite_episodes"]

STAGES: list[dict] = [{"support": "gantry", "chirp": True}, {}]
"""The recordings of one robot: PD-tracked joint chirps with the pelvis on a gantry, then scripted stepping in
place with a free pelvis on the plane (each 9 s, as v5's ``fixed`` and ``plane`` episodes)."""

SUITES: dict[str, dict] = {
    "identification": {
        "mid": {**MID, **NEW_MID_V5},
        "ool": OOL,
        "episode": {"duration": 9.0, "stages": STAGES},
    },
}
"""The one suite: v5's plane table (17 classes at mid strength), the two out-of-library classes, both stages."""

SEED_BASE: dict[str, int] = {"identification": 54000}
"""Fresh: v5 used 51000-53919, earlier benchmarks and calibrations stay below 30000."""

NULLS_PER_SUITE = 20
"""Null episodes (the false-positive rate's denominator)."""

V6 = Protocol("v6", SUITES, SEED_BASE, NULLS_PER_SUITE, carried={"sand": "v5/sand"})
"""Benchmark v6 as the runner reads it; the pool carries v5's sand suite over."""


def suite_episodes(suite: str) -> list[dict]:
    """Episode dicts of one v6 suite, in a fixed order (``sweep.run_episode`` input)."""
    return protocol.suite_episodes(V6, suite)


def _parse(argv: list[str] | None) -> tuple[Path, ProtocolRunCfg]:
    """The results folder and run config of the arguments (exit code 2 on a malformed or out-of-range one)."""
    return protocol.parse(V6, argv, __doc__)


def main(argv: list[str] | None = None) -> int:
    """Run (part of) the identification suite, then score it and the pool; exit 2 on bad arguments."""
    return protocol.main(V6, argv, __doc__)


if __name__ == "__main__":
    raise SystemExit(main())
