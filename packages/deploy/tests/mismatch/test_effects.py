# SPDX-License-Identifier: Apache-2.0
"""Effect library: vocabulary contract, exact nominal at zero, injection code independent of hypotheses."""

from __future__ import annotations

import ast
from dataclasses import replace
from pathlib import Path

import numpy as np

from gmloco.deploy.mismatch.effects import EFFECT_IDS, EFFECTS, effect
from gmloco.deploy.mismatch.g1model import G1_EFFORT_LIMIT
from gmloco.deploy.mismatch.recording import Recording
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


_THRESHOLD = ("actuator.torque_speed", "actuator.torque_limit")  # act only where torques reach the envelope


def test_each_effect_changes_the_simulation(null_rec: object) -> None:
    """Every effect moves the outputs: mid-range values, threshold (saturation) effects at their upper bound."""
    rp = Replayer(null_rec, ReplayCfg(horizon=12, stride=4))
    starts = rp.segment_starts()[:6]
    nominal = rp.simulate({}, starts)
    for e in EFFECTS:
        _, hi = e.bounds()
        sim = rp.simulate({e.id: hi if e.id in _THRESHOLD else 0.5 * hi}, starts)
        assert np.max(np.abs(sim - nominal)) > 0.0, e.id
    assert effect("actuator.delay").size == 1


def _no_damping(rec: Recording) -> Recording:
    """The recording with kd = 0, so the logged tau is the position term alone (no velocity-timing ambiguity)."""
    return replace(rec, kd=np.zeros_like(rec.kd))


def test_backlash_is_a_dead_band_of_the_position_loop(null_rec: Recording) -> None:
    """Simulated tau = kp (e - clip(e, -w/2, w/2)) + tau_ff on the leg joints, e = q_cmd - q_encoder (closed form)."""
    rec = _no_damping(null_rec)
    rp = Replayer(rec, ReplayCfg(horizon=12, stride=4))
    starts = rp.segment_starts()[:4]
    width = np.array([0.01, 0.04, 0.02])  # hip, knee, ankle [rad]
    out = rp.simulate({"actuator.backlash": width}, starts)
    k = starts[:, None] + rp.offsets[None, :]
    err = rec.q_cmd[k] - out[..., :29]
    half = 0.5 * np.tile(width[[0, 0, 0, 1, 2, 2]], 2)
    want = rec.kp[k][..., :12] * (err[..., :12] - np.clip(err[..., :12], -half, half)) + rec.tau_ff[k][..., :12]
    want = np.clip(want, -G1_EFFORT_LIMIT[:12], G1_EFFORT_LIMIT[:12])
    # float64 arithmetic on the same operands: a few ulp of the largest torque
    np.testing.assert_allclose(out[..., 58:70], want, rtol=0, atol=1e-9)
    assert np.any(np.abs(err[..., 3]) < 0.02)  # the knee error sits inside its band somewhere: the test can fail


def test_torque_limit_clips_at_the_reduced_limit(null_rec: Recording) -> None:
    """With a limit loss s, |tau| <= (1 - s) tau_max on every joint, and the bound is reached (it binds)."""
    rp = Replayer(null_rec, ReplayCfg(horizon=12, stride=4))
    starts = rp.segment_starts()[:6]
    loss = 0.85
    tau = rp.simulate({"actuator.torque_limit": np.array([loss])}, starts)[..., 58:87]
    lim = (1.0 - loss) * G1_EFFORT_LIMIT
    assert np.all(np.abs(tau) <= lim + 1e-12)
    assert np.any(np.isclose(np.abs(tau), lim, rtol=0, atol=1e-12))


def test_per_joint_friction_and_limb_mass_edit_only_their_targets(null_rec: Recording) -> None:
    """Leg friction, damping and limb masses land on their own joint or link and nowhere else (model arrays)."""
    rp = Replayer(null_rec, ReplayCfg(horizon=12, stride=4))
    starts = rp.segment_starts()[:2]
    m = rp.model
    mass0, inertia0 = m.body_mass.copy(), m.body_inertia.copy()
    fric0 = m.dof_frictionloss.copy()
    tau_c = np.zeros(12)
    tau_c[3] = 1.2  # left knee [N*m]
    dm = np.array([0.0, 0.0, 0.0, 1.5])  # right shank [kg]
    rp.simulate({"joint.coulomb_friction_leg": tau_c, "body.limb_mass": dm}, starts)
    dof = np.flatnonzero(m.dof_frictionloss != fric0)
    assert [m.joint(m.dof_jntid[i]).name for i in dof] == ["left_knee_joint"]
    np.testing.assert_allclose(m.dof_frictionloss[dof], fric0[dof] + 1.2, rtol=0, atol=1e-15)
    knee = m.body("right_knee_link").id
    assert np.flatnonzero(m.body_mass != mass0).tolist() == [knee]
    ratio = (mass0[knee] + 1.5) / mass0[knee]
    np.testing.assert_allclose(m.body_inertia[knee], inertia0[knee] * ratio, rtol=1e-15)


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


def test_ground_effects_are_exactly_inert_on_a_held_pelvis() -> None:
    """On a gantry recording every effect flagged ``ground`` leaves the replay bit for bit nominal."""
    from gmloco.deploy.mismatch.benchmark.chirp import ChirpCfg
    from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
    from gmloco.deploy.mismatch.benchmark.truth import TruthEffect

    rec, _ = generate(EpisodeCfg(effect=TruthEffect(), duration=1.0, seed=5, support="gantry", chirp=ChirpCfg()))
    rp = Replayer(rec, ReplayCfg(horizon=12, stride=4))
    starts = rp.segment_starts()[:4]
    nominal = rp.simulate({}, starts)
    ground = [e for e in EFFECTS if e.ground]
    assert {e.id for e in ground} == {i for i in EFFECT_IDS if i.startswith("terrain.")}
    for e in ground:
        _, hi = e.bounds()
        np.testing.assert_array_equal(rp.simulate({e.id: hi}, starts), nominal, err_msg=e.id)
