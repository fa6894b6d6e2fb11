# SPDX-License-Identifier: Apache-2.0
"""Strength tables and episode lists: the stock (v3) tables are unchanged, v4 applies the tolerance rule."""

from __future__ import annotations

import pytest

from gmloco.deploy.mismatch.benchmark.episodes import (
    MID,
    MID_TOLERANCE_FACTOR,
    SAND_MID,
    STRENGTH_TABLES,
    episode_list,
    sand_episode_list,
    tolerance_ratio,
)

_OFF = [0.0] * 12
_OFF[3], _OFF[6], _OFF[4] = 0.03, -0.03, 0.02
_COMMON = {
    "actuator.delay": {"delay": [0.008]},
    "actuator.gain_scale": {"kp_scale": [-0.2]},
    "joint.coulomb_friction": {"tau_c": [1.5]},
    "joint.viscous_damping": {"b": [1.0]},
    "joint.armature": {"scale": [1.5]},
    "sensor.encoder_offset": {"offset": _OFF},
    "imu.gyro_bias": {"bias": [0.03, -0.02, 0.015]},
    "imu.misalignment": {"angle": [0.03, -0.04]},
    "body.mass_error": {"delta_mass": [4.0]},
}
V3_PLANE = {
    **_COMMON,
    "terrain.stiffness_scale": {"zeta": [2.0]},
    "terrain.cohesion": {"cohesion": [6000.0]},
    "actuator.torque_speed": {"droop": [0.05]},
}
V3_SAND = {
    **_COMMON,
    "actuator.torque_speed": {"droop": [0.18]},
    "terrain.stiffness_scale": {"zeta": [0.5]},
    "terrain.depth_hardening": {"kappa": [60.0]},
    "terrain.rate_drag": {"rho_drag": [1.0e5]},
    "terrain.cohesion": {"cohesion": [3000.0]},
}
"""The mid strengths of every run through v3, written out (the default table must reproduce them)."""


def test_default_table_is_v3_unchanged() -> None:
    """Without a table, both suites' lists carry v3's strengths in v3's order, names and seeds."""
    assert MID == V3_PLANE and list(MID) == list(V3_PLANE)
    assert SAND_MID == V3_SAND and list(SAND_MID) == list(V3_SAND)
    assert STRENGTH_TABLES["v3"] == {"plane": V3_PLANE, "sand": V3_SAND}
    assert sand_episode_list(2, 48, seed_offset=10000) == sand_episode_list(2, 48, seed_offset=10000, table="v3")
    assert episode_list(2, 20, seed_offset=10000) == episode_list(2, 20, seed_offset=10000, table="v3")
    sand = {e["effect"]: e["params"] for e in sand_episode_list(1, 0, seed_offset=10000)}
    assert {k: v for k, v in sand.items() if not k.startswith("ool.")} == V3_SAND
    plane = {e["effect"]: e["params"] for e in episode_list(1, 0)}
    assert {k: v for k, v in plane.items() if not k.startswith("ool.")} == V3_PLANE


def test_v4_table_differs_only_where_the_tolerance_rule_says() -> None:
    """v4 = v3 with every class below 1.5x its tolerance raised to 1.5x: only depth hardening, 60 -> 150 1/m."""
    assert MID_TOLERANCE_FACTOR == 1.5
    v3, v4 = STRENGTH_TABLES["v3"], STRENGTH_TABLES["v4"]
    for suite in ("plane", "sand"):
        assert list(v4[suite]) == list(v3[suite])
        below = {k for k, p in v3[suite].items() if tolerance_ratio(k, p) < MID_TOLERANCE_FACTOR}
        changed = {k for k in v3[suite] if v3[suite][k] != v4[suite][k]}
        assert changed == below
        assert all(tolerance_ratio(k, p) >= MID_TOLERANCE_FACTOR for k, p in v4[suite].items())
    assert v4["plane"] == V3_PLANE
    assert v4["sand"]["terrain.depth_hardening"] == {"kappa": [150.0]}
    assert tolerance_ratio("terrain.depth_hardening", {"kappa": [60.0]}) == pytest.approx(0.6)
    assert tolerance_ratio("terrain.depth_hardening", {"kappa": [150.0]}) == pytest.approx(1.5)
    with pytest.raises(ValueError, match="unknown strength table"):
        sand_episode_list(1, 1, table="v5")


def _v4_lists() -> tuple[list[dict], list[dict]]:
    """The v4 protocol's lists: composite sand with 64 nulls, plane with 20 nulls, 2 seeds, offset 20 000."""
    sand = sand_episode_list(2, 64, seed_offset=20000, motion="composite", table="v4")
    plane = episode_list(2, 20, seed_offset=20000, table="v4")
    return sand, plane


def test_v4_episode_lists_match_the_protocol_table() -> None:
    """96 composite sand episodes and 48 plane episodes with the protocol's names and seeds."""
    sand, plane = _v4_lists()
    assert len(sand) == 96 and len(plane) == 48
    mids = [e for e in sand if e["strength"] == "mid" and not e["effect"].startswith("ool.")]
    assert len(mids) == 28 and {e["seed"] for e in mids} == {22000, 22001}
    assert {e["name"] for e in mids} == {f"sandc-{k}-mid-{i}" for k in V3_SAND for i in (0, 1)}
    sn = [e for e in sand if e["effect"] == "none"]
    assert [e["name"] for e in sn] == [f"sandc-none-{i}" for i in range(64)]
    assert [e["seed"] for e in sn] == list(range(23000, 23064))
    so = [(e["name"], e["seed"]) for e in sand if e["effect"].startswith("ool.")]
    assert sorted(so) == sorted(
        (f"sandc-ool.{k}-{i}", 22100 + i) for k in ("current_lag", "shank_length") for i in (0, 1)
    )
    assert all(e["motion"] == "composite" and e["ground"] == "sand" for e in sand)
    kappa = {e["name"]: e["params"] for e in sand if e["effect"] == "terrain.depth_hardening"}
    assert kappa == {f"sandc-terrain.depth_hardening-mid-{i}": {"kappa": [150.0]} for i in (0, 1)}
    pm = [e for e in plane if e["strength"] == "mid" and not e["effect"].startswith("ool.")]
    assert {e["name"] for e in pm} == {f"{k}-mid-{i}" for k in V3_PLANE for i in (0, 1)}
    assert {e["seed"] for e in pm} == {20100, 20101}
    pn = [e for e in plane if e["effect"] == "none"]
    assert [(e["name"], e["seed"]) for e in pn] == [(f"none-{i}", 21000 + i) for i in range(20)]
    po = [(e["name"], e["seed"]) for e in plane if e["effect"].startswith("ool.")]
    assert sorted(po) == sorted((f"ool.{k}-{i}", 20300 + i) for k in ("current_lag", "shank_length") for i in (0, 1))


def test_v4_lists_split_into_eight_parts_of_12_sand_and_6_plane_episodes() -> None:
    """``--part P/8``: disjoint parts covering each list, 12 sand and 6 plane episodes each."""
    from gmloco.deploy.mismatch.benchmark.sweep import _part

    for eps, size in zip(_v4_lists(), (12, 6), strict=True):
        parts = [_part(eps, f"{p}/8") for p in range(8)]
        assert [len(x) for x in parts] == [size] * 8
        names = [e["name"] for x in parts for e in x]
        assert sorted(names) == sorted(e["name"] for e in eps) and len(set(names)) == len(eps)
