# SPDX-License-Identifier: Apache-2.0
"""The serial plane replay equals the side-by-side replay bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from gmloco.deploy.mismatch.benchmark.chirp import ChirpCfg
from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
from gmloco.deploy.mismatch.benchmark.truth import TruthEffect
from gmloco.deploy.mismatch.recording import Recording
from gmloco.deploy.mismatch.replay import N_CHANNELS, Replayer, _unpack

_PARAMS = [
    {},
    {"actuator.delay": np.array([0.004]), "joint.coulomb_friction": np.array([1.0])},
    {"actuator.backlash": np.array([0.01, 0.02, 0.01]), "body.limb_mass": np.array([0.5, 0.0, 0.0, 0.3])},
    {"terrain.rate_drag": np.array([2000.0]), "terrain.cohesion": np.array([500.0])},
    {"actuator.torque_speed": np.array([0.05]), "imu.misalignment": np.array([0.01, -0.02])},
    {
        "actuator.torque_limit": np.array([0.4]),
        "actuator.gain_scale": np.array([0.1]),
        "sensor.encoder_offset": np.full(12, 0.01),
        "joint.viscous_damping_leg": np.full(12, 0.5),
    },
]


def _side_by_side(rp: Replayer, params: dict[str, np.ndarray], starts: np.ndarray) -> np.ndarray:
    """The side-by-side loop the sand ground uses, run on this replayer's ground."""
    h = _unpack(params)
    rp._set_model(h)
    out = np.zeros((len(starts), len(rp.offsets), N_CHANNELS))
    return rp._simulate_side_by_side(h, rp.base(params, starts), starts, out)


@pytest.mark.parametrize(
    "params", _PARAMS, ids=["nominal", "delay_friction", "backlash_limbs", "terrain", "droop", "limit_gain_offset"]
)
def test_serial_replay_is_bit_identical_on_the_plane(null_rec: Recording, params: dict[str, np.ndarray]) -> None:
    """Segments share no force on the plane, so replaying them one by one changes no bit of the output."""
    rp = Replayer(null_rec)
    starts = rp.segment_starts()[:12]
    np.testing.assert_array_equal(rp.simulate(params, starts), _side_by_side(rp, params, starts))


def test_serial_replay_is_bit_identical_with_a_welded_pelvis() -> None:
    """The welded pelvis moves per segment through the shared model; the serial order keeps every bit."""
    rec, _ = generate(
        EpisodeCfg(effect=TruthEffect(), duration=1.5, seed=5, support="gantry", chirp=ChirpCfg(duration=1.5))
    )
    rp = Replayer(rec)
    starts = rp.segment_starts()[:8]
    params = {"joint.armature": np.array([0.5]), "imu.gyro_bias": np.array([0.01, 0.0, -0.02])}
    np.testing.assert_array_equal(rp.simulate(params, starts), _side_by_side(rp, params, starts))


def test_a_segment_subset_replays_as_in_the_full_replay(null_rec: Recording) -> None:
    """Screening replays only the training segments: each segment's output must not depend on the others."""
    rp = Replayer(null_rec)
    starts = rp.segment_starts()[:9]
    keep = np.arange(len(starts)) % 3 != 2
    params = {"sensor.encoder_offset": np.full(12, 0.01)}
    np.testing.assert_array_equal(rp.simulate(params, starts[keep]), rp.simulate(params, starts)[keep])
