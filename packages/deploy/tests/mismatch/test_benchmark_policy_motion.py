# SPDX-License-Identifier: Apache-2.0
"""The sand suite's policy command schedules: the stock 1 m/s walk and the composite motion (CPU, fast)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gmloco.deploy.mismatch.benchmark.episodes import sand_episode_list
from gmloco.deploy.mismatch.benchmark.policy_motion import (
    COMPOSITE_SCHEDULE,
    MOTIONS,
    PolicyMotion,
    PolicyMotionCfg,
    motion_cfg,
)


def test_walk_is_the_stock_command() -> None:
    """``walk``: zero for 0.5 s, then 1 m/s forward, no turn (the suite's command through v3)."""
    cfg = motion_cfg("walk")
    assert cfg == PolicyMotionCfg() and MOTIONS["walk"] == 8.0
    np.testing.assert_array_equal(cfg.command(0.0), [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(cfg.command(0.49), [0.0, 0.0, 0.0])
    for t in (0.5, 3.0, 7.99):
        np.testing.assert_array_equal(cfg.command(t), [1.0, 0.0, 0.0])


def test_composite_schedule_stands_then_walks_at_three_speeds_then_turns() -> None:
    """Stand 3 s, 0.5 / 1.0 / 1.5 m/s, then a left turn, inside the recording and the policy's training ranges."""
    cfg = motion_cfg("composite")
    starts = [s[0] for s in COMPOSITE_SCHEDULE]
    assert starts[0] == 0.0 and starts == sorted(starts) and starts[-1] < MOTIONS["composite"] - 2.0
    expect = {
        0.0: [0, 0, 0],
        2.99: [0, 0, 0],
        3.0: [0.5, 0, 0],
        6.9: [0.5, 0, 0],
        7.0: [1.0, 0, 0],
        12.0: [1.5, 0, 0],
        14.0: [0.8, 0, 0.5],
        17.99: [0.8, 0, 0.5],
    }
    for t, cmd in expect.items():
        np.testing.assert_allclose(cfg.command(t), cmd, err_msg=f"t = {t}")
    # a policy step that lands a rounding error before a boundary takes the new segment
    np.testing.assert_allclose(cfg.command(3.0 - 1e-12), [0.5, 0, 0])
    # stage-two command ranges of the granular task: forward -1..1.7 m/s, yaw rate -0.7..0.7 rad/s
    assert all(-1.0 <= s[1] <= 1.7 and abs(s[2]) <= 0.5 and abs(s[3]) <= 0.7 for s in COMPOSITE_SCHEDULE)
    with pytest.raises(ValueError, match="unknown motion"):
        motion_cfg("run")


def test_policy_sees_the_scheduled_command() -> None:
    """The ``command`` term of the policy's observation is the schedule's value at each policy step."""
    policy = PolicyMotion(motion_cfg("composite"))
    seen: list[np.ndarray] = []

    class Sess:
        def __init__(self, inner: object) -> None:
            self.inner = inner

        def get_inputs(self) -> list:
            return self.inner.get_inputs()  # type: ignore[attr-defined]

        def run(self, names: object, feeds: dict) -> list:
            seen.append(next(iter(feeds.values()))[0].copy())
            return [np.zeros((1, 29), np.float32)]

    policy.sess = Sess(policy.sess)  # type: ignore[assignment]
    i = policy.names.index("command")
    start = sum(d * policy.hist for d in policy.dims[:i])
    newest = slice(start + (policy.hist - 1) * 3, start + policy.hist * 3)
    quat, zero = np.array([1.0, 0, 0, 0]), np.zeros(3)
    for t in (1.0, 4.0, 8.0, 12.0, 15.0):
        policy.next_t = t  # one action per call
        policy.targets(t, quat, zero, policy.q0.copy(), np.zeros(29))
        np.testing.assert_allclose(seen[-1][newest], policy.cfg.command(t), atol=1e-7)
    assert [float(s[newest][2]) for s in seen] == [0.0, 0.0, 0.0, 0.0, 0.5]


def test_composite_sand_list_has_its_own_names_and_the_same_seeds() -> None:
    """``sandc-*`` names, the motion in every episode; the stock list keeps its ``sand-*`` names and seeds."""
    walk, comp = sand_episode_list(2, 4), sand_episode_list(2, 4, motion="composite")
    assert all(e["name"].startswith("sand-") and e["motion"] == "walk" for e in walk)
    assert all(e["name"].startswith("sandc-") and e["motion"] == "composite" for e in comp)
    assert [e["name"].replace("sand-", "sandc-", 1) for e in walk] == [e["name"] for e in comp]
    assert [e["seed"] for e in walk] == [e["seed"] for e in comp]
    with pytest.raises(ValueError, match="unknown motion"):
        sand_episode_list(1, 1, motion="run")


def test_sweep_records_the_sand_motion_in_the_manifest(tmp_path: Path) -> None:
    """``--motion composite``: the manifest holds the schedule; nothing runs past a negative deadline."""
    from gmloco.deploy.mismatch.benchmark.sweep import main

    main(
        [
            "--out",
            str(tmp_path),
            "--suite",
            "sand",
            "--motion",
            "composite",
            "--only",
            "sandc-none-",
            "--nulls",
            "1",
            "--workers",
            "1",
            "--deadline-s",
            "-1",
        ]
    )
    inv = json.loads((tmp_path / "manifest.json").read_text())["invocations"][-1]
    assert inv["policy_motion"]["name"] == "composite"
    assert [list(s) for s in inv["policy_motion"]["schedule"]] == [list(s) for s in COMPOSITE_SCHEDULE]
    assert json.loads((tmp_path / "summary.json").read_text())["missing"] == ["sandc-none-0"]
