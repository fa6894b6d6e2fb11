# SPDX-License-Identifier: Apache-2.0
"""Replay settings follow the recording's rate: the 500 Hz defaults' times, in its samples (MPM logs are 50 Hz)."""

from __future__ import annotations

import numpy as np
import pytest

from gmloco.deploy.mismatch.benchmark.controller import MotionCfg
from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
from gmloco.deploy.mismatch.benchmark.truth import TruthEffect
from gmloco.deploy.mismatch.pipeline import AnalysisCfg
from gmloco.deploy.mismatch.problem import Problem
from gmloco.deploy.mismatch.replay import ReplayCfg, Replayer, replay_cfg_for_rate, sand_replay_cfg


def test_at_500_hz_the_rate_aware_settings_are_the_defaults() -> None:
    """Plane: ``ReplayCfg()``; sand: 1 ms steps, two per sample, 30-sample horizon compared every third."""
    assert replay_cfg_for_rate(500.0) == ReplayCfg()
    sand = replay_cfg_for_rate(500.0, "sand", "poppy_seed")
    assert (sand.horizon, sand.stride, sand.substeps, sand.attitude_half_window) == (30, 3, 2, 8)
    assert sand.sim.timestep == pytest.approx(0.001) and sand.sim.sand.material == "poppy_seed"
    assert sand_replay_cfg("poppy_seed") == sand


def test_at_50_hz_the_steps_and_spans_keep_their_times() -> None:
    """A 50 Hz log: 10 plane / 20 sand physics steps per sample, a 60 ms horizon of 3 samples, each compared."""
    plane, sand = replay_cfg_for_rate(50.0), replay_cfg_for_rate(50.0, "sand")
    assert (plane.substeps, sand.substeps) == (10, 20)
    assert plane.sim.timestep == pytest.approx(0.002) and sand.sim.timestep == pytest.approx(0.001)
    assert (plane.horizon, plane.stride, plane.attitude_half_window) == (3, 1, 1)
    assert replay_cfg_for_rate(50.0, horizon=5).horizon == 5


@pytest.mark.parametrize(
    ("rate", "ground", "horizon"), [(0.0, "plane", None), (50.0, "gravel", None), (50.0, "plane", 0)]
)
def test_bad_rate_ground_or_horizon_is_refused(rate: float, ground: str, horizon: int | None) -> None:
    """A clear error instead of a replay at the wrong time base."""
    with pytest.raises(ValueError, match=r"rate_hz|ground|horizon"):
        replay_cfg_for_rate(rate, ground, horizon=horizon)


def test_a_50_hz_null_recording_replays_near_its_floor_only_at_its_own_rate() -> None:
    """A 50 Hz stepping null (2 ms truth physics) replays near its floor only at its own rate.

    The rate-aware replay's residual energy is a few floors; the 500 Hz settings (one 2 ms step per 20 ms sample)
    miss the time base by 10x and leave ~20x more.
    """
    rec, key = generate(EpisodeCfg(effect=TruthEffect(), duration=4.0, seed=3, rate_hz=50.0, substeps=10,
                                   motion=MotionCfg(kind="step", stand_time=0.3)))  # fmt: skip
    assert key.get("fell_at_s") is None and rec.n == 200

    def energy(cfg: ReplayCfg) -> float:
        pb = Problem(Replayer(rec, cfg), AnalysisCfg().floor)
        assert len(pb.starts) >= 60
        return float(np.mean(pb.resid({}) ** 2))

    right, wrong = energy(replay_cfg_for_rate(50.0)), energy(ReplayCfg(horizon=3))
    assert right < 10.0 and wrong > 10.0 * right
