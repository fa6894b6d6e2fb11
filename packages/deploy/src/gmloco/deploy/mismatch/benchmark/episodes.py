# SPDX-License-Identifier: Apache-2.0
"""Benchmark episode list: each library effect at three strengths, nulls, and out-of-library effects."""

from __future__ import annotations

__all__ = [
    "MID",
    "MID_TOLERANCE_FACTOR",
    "SAND_MID",
    "SAND_MID_V4",
    "STRENGTHS",
    "STRENGTH_TABLES",
    "episode_list",
    "sand_episode_list",
    "tolerance_ratio",
]

_OFF = [0.0] * 12
_OFF[3], _OFF[6], _OFF[4] = 0.03, -0.03, 0.02  # left knee, right hip pitch, left ankle pitch [rad]

MID: dict[str, dict[str, list[float]]] = {
    "actuator.delay": {"delay": [0.008]},
    "actuator.gain_scale": {"kp_scale": [-0.2]},
    "joint.coulomb_friction": {"tau_c": [1.5]},
    "joint.viscous_damping": {"b": [1.0]},
    "joint.armature": {"scale": [1.5]},
    "sensor.encoder_offset": {"offset": _OFF},
    "imu.gyro_bias": {"bias": [0.03, -0.02, 0.015]},
    "imu.misalignment": {"angle": [0.03, -0.04]},
    "body.mass_error": {"delta_mass": [4.0]},
    "terrain.stiffness_scale": {"zeta": [2.0]},
    "terrain.cohesion": {"cohesion": [6000.0]},
    "actuator.torque_speed": {"droop": [0.05]},
}
"""Mid-strength truth parameters per effect (tool units)."""

STRENGTHS: dict[str, float] = {"low": 0.4, "mid": 1.0, "high": 2.0}
"""Multipliers of the mid strength."""

OOL: dict[str, dict[str, list[float]]] = {"ool.shank_length": {"dl": [0.03]}, "ool.current_lag": {"tau_lag": [0.01]}}
"""Out-of-library effects (the right answer is ``unexplained``)."""


def episode_list(
    seeds: int = 1,
    nulls: int = 20,
    strengths: tuple[str, ...] = ("mid",),
    seed_offset: int = 0,
    table: str = "v3",
) -> list[dict]:
    """Return episode dicts ``{name, effect, params, strength, seed}``.

    ``seed_offset`` is added to every seed (fresh test seeds for a re-run; names are unchanged). ``table`` names
    the mid-strength table (:data:`STRENGTH_TABLES`; the plane's is :data:`MID` in both ``v3`` and ``v4``).
    """
    mid = _table(table)["plane"]
    eps = []
    for s in strengths:
        for eid, p in mid.items():
            for seed in range(seeds):
                scaled = {k: [v * STRENGTHS[s] for v in vals] for k, vals in p.items()}
                eps.append(
                    {
                        "name": f"{eid}-{s}-{seed}",
                        "effect": eid,
                        "params": scaled,
                        "strength": s,
                        "seed": 100 + seed + seed_offset,
                    }
                )
    for seed in range(nulls):
        # Seeds 1000+ are disjoint from the nulls (200-211) that set the floors and ``weak_gain_min``.
        eps.append(
            {
                "name": f"none-{seed}",
                "effect": "none",
                "params": {},
                "strength": "none",
                "seed": 1000 + seed + seed_offset,
            }
        )
    for eid, p in OOL.items():
        for seed in range(max(1, seeds)):
            eps.append(
                {
                    "name": f"{eid}-{seed}",
                    "effect": eid,
                    "params": p,
                    "strength": "mid",
                    "seed": 300 + seed + seed_offset,
                }
            )
    return eps


SAND_MID: dict[str, dict[str, list[float]]] = {
    **{k: v for k, v in MID.items() if not k.startswith("terrain.") and k != "actuator.torque_speed"},
    "actuator.torque_speed": {"droop": [0.18]},
    "terrain.stiffness_scale": {"zeta": [0.5]},
    "terrain.depth_hardening": {"kappa": [60.0]},
    "terrain.rate_drag": {"rho_drag": [1.0e5]},
    "terrain.cohesion": {"cohesion": [3000.0]},
}
"""Mid strengths on the sand suite (walking policy on 3D-RFT dry sand): all 14 library effects. Fixed before
the suite's test episodes were run. The terrain and saturation values were set on tuning seed 204 from the
oracle held-out gain of the true model (never the tool's answer): zeta 0.5 -> 0.78, kappa 60 1/m -> 0.89,
cohesion 3 kPa -> 0.47, rho_drag 1.5e4 -> 0.08 (too weak) then 1e5 -> 0.62, droop 0.1 and 0.15 s/rad -> 0.00
(the envelope never binds) then 0.18 -> 0.99 (binds at push-off in ~7 % of samples)."""

SAND_OOL: dict[str, dict[str, list[float]]] = {
    "ool.shank_length": {"dl": [0.03]},
    "ool.current_lag": {"tau_lag": [0.01]},
}
"""Out-of-library effects of the sand suite."""


SAND_MID_V4: dict[str, dict[str, list[float]]] = {**SAND_MID, "terrain.depth_hardening": {"kappa": [150.0]}}
"""Mid strengths of the sand suite for benchmark v4 (``results/mismatch_benchmark/v4/PROTOCOL.md``): v3's
:data:`SAND_MID` with the rule :data:`MID_TOLERANCE_FACTOR` applied. Depth hardening's 60 1/m was 0.6x its
100 1/m tolerance and becomes 150 1/m (1.5x); every other class of both suites already met the rule. Chosen
with the composite-motion tuning episodes (seeds 500-551) known."""

MID_TOLERANCE_FACTOR = 1.5
"""Benchmark v4's rule: every class's mid strength is at least this multiple of its effect's ``tolerance``, in the
measure of :func:`tolerance_ratio` (a truth below the tolerance cannot pass ``attribution.confirm``'s size test)."""

STRENGTH_TABLES: dict[str, dict[str, dict[str, dict[str, list[float]]]]] = {
    "v3": {"plane": MID, "sand": SAND_MID},
    "v4": {"plane": MID, "sand": SAND_MID_V4},
}
"""Named mid-strength tables per suite: ``v3`` (the stock tables, every run through v3) and ``v4``."""


def _table(name: str) -> dict[str, dict[str, dict[str, list[float]]]]:
    """The strength table called ``name`` (a key of :data:`STRENGTH_TABLES`)."""
    if name not in STRENGTH_TABLES:
        raise ValueError(f"unknown strength table {name!r}; known: {sorted(STRENGTH_TABLES)}")
    return STRENGTH_TABLES[name]


def tolerance_ratio(effect_id: str, params: dict[str, list[float]]) -> float:
    """Largest ``|theta_i| / tolerance_i`` over the effect's parameter components (the size test's measure)."""
    import numpy as np

    from gmloco.deploy.mismatch.effects import effect

    spec = effect(effect_id)
    theta = np.concatenate([np.ravel(np.asarray(params[p.name], float)) for p in spec.params])
    return float(np.max(np.abs(theta) / spec.flat("tolerance")))


def sand_episode_list(
    seeds: int = 1,
    nulls: int = 6,
    material: str = "dry_sand",
    seed_offset: int = 0,
    motion: str = "walk",
    table: str = "v3",
) -> list[dict]:
    """Episodes of the sand suite: the walking policy on 3D-RFT sand, logged odometry (mocap).

    ``motion`` names the command schedule (``policy_motion.MOTIONS``): ``walk`` (1 m/s, the suite through v3;
    names ``sand-*``) or ``composite`` (stand, three speeds, a turn; names ``sandc-*``). Every episode carries
    its ``motion``. Seeds 2000+ (effects), 2100+ (out of library) and 3000+ (nulls) are disjoint from the tuning
    nulls (200-203) that set the sand floors; ``seed_offset`` is added to every seed (names are unchanged).
    ``table`` names the mid-strength table (:data:`STRENGTH_TABLES`): ``v3`` is :data:`SAND_MID`, ``v4``
    :data:`SAND_MID_V4` (names are unchanged).
    """
    from gmloco.deploy.mismatch.benchmark.policy_motion import MOTIONS

    if motion not in MOTIONS:
        raise ValueError(f"unknown motion {motion!r}; known: {sorted(MOTIONS)}")
    pre = "sand" if motion == "walk" else "sandc"
    mid = _table(table)["sand"]
    common = {"ground": "sand", "material": material, "policy": True, "odometry": True, "motion": motion}
    eps = []
    for eid, p in mid.items():
        for seed in range(seeds):
            eps.append(
                {
                    "name": f"{pre}-{eid}-mid-{seed}",
                    "effect": eid,
                    "params": p,
                    "strength": "mid",
                    "seed": 2000 + seed + seed_offset,
                }
            )
    for seed in range(nulls):
        eps.append(
            {
                "name": f"{pre}-none-{seed}",
                "effect": "none",
                "params": {},
                "strength": "none",
                "seed": 3000 + seed + seed_offset,
            }
        )
    for eid, p in SAND_OOL.items():
        for seed in range(max(1, seeds)):
            eps.append(
                {
                    "name": f"{pre}-{eid}-{seed}",
                    "effect": eid,
                    "params": p,
                    "strength": "mid",
                    "seed": 2100 + seed + seed_offset,
                }
            )
    return [{**e, **common} for e in eps]
