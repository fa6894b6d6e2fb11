# SPDX-License-Identifier: Apache-2.0
"""Benchmark v5: three suites (plane stepping, sand composite walking, fixed-base chirp), pre-registered.

The protocol is ``results/mismatch_benchmark/v5/protocol.md``; this module is its runner. Usage::

    python -m gmloco.deploy.mismatch.benchmark.v5 --out results/mismatch_benchmark/v5 --suite fixed
        [--workers N] [--part I/N] [--resume] [--deadline-s S] [--list] [--score-only]

Every suite has two seeds per library class at mid strength, two per out-of-library class and
``NULLS_PER_SUITE`` nulls. The seeds are fixed here (``SEED_BASE``) and fresh: no earlier benchmark, floor
calibration or tuning run used them. The runner is :mod:`.protocol`'s: rows go to ``OUT/<suite>/rows``,
``OUT/<suite>/summary.json`` scores one suite and ``OUT/summary_pooled.json`` pools every suite scored so far.
"""

from __future__ import annotations

from pathlib import Path

from gmloco.deploy.mismatch.benchmark import protocol
from gmloco.deploy.mismatch.benchmark.episodes import MID, OOL, SAND_MID_V4, SAND_OOL
from gmloco.deploy.mismatch.benchmark.protocol import FLAGS, TARGETS, Protocol, pooled
from gmloco.deploy.mismatch.benchmark.protocol_cfg import ProtocolRunCfg

__all__ = [
    "FIXED_MID_V5",
    "FLAGS",
    "NEW_MID_V5",
    "NULLS_PER_SUITE",
    "SEED_BASE",
    "SUITES",
    "TARGETS",
    "V5",
    "main",
    "pooled",
    "suite_episodes",
]

_LEG = 12
_KNEE_L, _HIP_PITCH_R, _ANKLE_PITCH_R = 3, 6, 10  # leg-joint indices (G1_JOINT_NAMES order)


def _leg(values: dict[int, float]) -> list[float]:
    """A 12-vector over the leg joints, zero except at the given indices."""
    out = [0.0] * _LEG
    for i, v in values.items():
        out[i] = v
    return out


NEW_MID_V5: dict[str, dict[str, list[float]]] = {
    "actuator.torque_limit": {"limit_loss": [0.4]},
    "actuator.backlash": {"width": [0.0, 0.02, 0.0]},
    "body.limb_mass": {"delta_mass": [0.0, 0.0, 1.0, 0.0]},
    "joint.coulomb_friction_leg": {"tau_c": _leg({_KNEE_L: 2.0, _ANKLE_PITCH_R: 1.0})},
    "joint.viscous_damping_leg": {"b": _leg({_KNEE_L: 1.0, _HIP_PITCH_R: 0.6})},
}
"""Mid strengths of the classes v5 adds (every component that is set is >= 1.5x its tolerance, v4's rule):
a 40 % lower peak torque, 0.02 rad knee backlash, +1 kg on the left shank, left-knee / right-ankle-pitch dry
friction 2 / 1 N*m, left-knee / right-hip-pitch damping 1 / 0.6 N*m*s/rad."""

FIXED_MID_V5: dict[str, dict[str, list[float]]] = {
    **{k: v for k, v in MID.items() if not k.startswith("terrain.")},
    **NEW_MID_V5,
}
"""Fixed-base chirp suite: every library class that can act on a held robot (no terrain class)."""

SUITES: dict[str, dict] = {
    "plane": {
        "mid": {**MID, **NEW_MID_V5},
        "ool": OOL,
        "episode": {"duration": 9.0},
    },
    "sand": {
        "mid": {**SAND_MID_V4, **NEW_MID_V5},
        "ool": SAND_OOL,
        "episode": {
            "duration": 18.0,
            "ground": "sand",
            "material": "dry_sand",
            "policy": True,
            "odometry": True,
            "motion": "composite",
        },
    },
    "fixed": {
        "mid": FIXED_MID_V5,
        "ool": OOL,
        "episode": {"duration": 9.0, "support": "gantry", "chirp": True},
    },
}
"""Per suite: mid-strength table, out-of-library classes, and the episode fields every episode carries."""

SEED_BASE: dict[str, int] = {"plane": 51000, "sand": 52000, "fixed": 53000}
"""First seed of each suite; classes take ``base + 10 i + s``, out-of-library ``base + 500 + 10 j + s``, nulls
``base + 900 + n``. Fresh: every earlier benchmark and calibration seed is below 30000."""

NULLS_PER_SUITE = 20
"""Null episodes per suite (the false-positive rate's denominator)."""

V5 = Protocol("v5", SUITES, SEED_BASE, NULLS_PER_SUITE)
"""Benchmark v5 as the runner reads it."""


def suite_episodes(suite: str) -> list[dict]:
    """Episode dicts of one v5 suite, in a fixed order (``sweep.run_episode`` input)."""
    return protocol.suite_episodes(V5, suite)


def _parse(argv: list[str] | None) -> tuple[Path, ProtocolRunCfg]:
    """The results folder and run config of the arguments (exit code 2 on a malformed or out-of-range one)."""
    return protocol.parse(V5, argv, __doc__)


def main(argv: list[str] | None = None) -> int:
    """Run (part of) one v5 suite, then score it and the pool; exit 2 on bad arguments."""
    return protocol.main(V5, argv, __doc__)


if __name__ == "__main__":
    raise SystemExit(main())
