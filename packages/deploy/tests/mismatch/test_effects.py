# SPDX-License-Identifier: Apache-2.0
"""Effect library: vocabulary contract, exact nominal at zero, injection code independent of hypotheses."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np

from gmloco.deploy.mismatch.effects import EFFECT_IDS, EFFECTS, effect
from gmloco.deploy.mismatch.replay import ReplayCfg, Replayer


def test_vocabulary_is_stable_and_complete() -> None:
    """The library has >= 10 unique ids covering the issue's required physics."""
    assert len(EFFECT_IDS) == len(set(EFFECT_IDS)) >= 10
    for required in (
        "actuator.delay",
        "joint.coulomb_friction",
        "joint.viscous_damping",
        "joint.armature",
        "actuator.torque_speed",
        "actuator.gain_scale",
        "sensor.encoder_offset",
        "imu.misalignment",
        "body.mass_error",
        "terrain.stiffness_scale",
        "terrain.depth_hardening",
        "terrain.rate_drag",
        "terrain.cohesion",
    ):
        assert required in EFFECT_IDS
    for e in EFFECTS:
        lo, hi = e.bounds()
        assert np.all(lo <= 0.0) and np.all(hi >= 0.0), e.id  # zero (nominal) is always admissible
        assert len(e.labels()) == e.size


def test_each_effect_exactly_nominal_at_zero(null_rec: object) -> None:
    """Simulating with an all-zero parameter vector of any effect reproduces the nominal replay bit for bit."""
    rp = Replayer(null_rec, ReplayCfg(horizon=12, stride=4))
    starts = rp.segment_starts()[:4]
    nominal = rp.simulate({}, starts)
    for e in EFFECTS:
        np.testing.assert_array_equal(rp.simulate({e.id: np.zeros(e.size)}, starts), nominal, err_msg=e.id)


def test_each_effect_changes_the_simulation(null_rec: object) -> None:
    """A mid-range value of every effect (except saturation, which needs torque near the limit) moves the outputs."""
    rp = Replayer(null_rec, ReplayCfg(horizon=12, stride=4))
    starts = rp.segment_starts()[:6]
    nominal = rp.simulate({}, starts)
    for e in EFFECTS:
        _, hi = e.bounds()
        sim = rp.simulate({e.id: 0.5 * hi}, starts)
        if e.id != "actuator.torque_speed":
            assert np.max(np.abs(sim - nominal)) > 0.0, e.id
    assert effect("actuator.delay").size == 1


def test_injection_code_is_independent_of_hypothesis_code() -> None:
    """The truth generator never imports the replay, terrain or attribution modules the tool fits with."""
    bench = Path(__file__).parents[2] / "src/gmloco/deploy/mismatch/benchmark"
    forbidden = {
        "gmloco.deploy.mismatch.replay",
        "gmloco.deploy.mismatch.terrain",
        "gmloco.deploy.mismatch.attribution",
        "gmloco.deploy.mismatch.problem",
        "gmloco.deploy.mismatch.sand",
    }
    for f in ("truth.py", "truth_sand.py", "generator.py", "controller.py", "policy_motion.py"):
        tree = ast.parse((bench / f).read_text())
        mods = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
        assert not mods & forbidden, f
