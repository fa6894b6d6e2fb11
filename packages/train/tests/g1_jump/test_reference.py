# SPDX-License-Identifier: Apache-2.0
"""The shipped jump references are dynamically plausible on rigid ground (inverse dynamics on the G1 model)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from gmloco.train.tasks.g1_jump.ik import IkCfg, g1_joint_limits, load_g1_model
from gmloco.train.tasks.g1_jump.plausibility import PlausibilityReport, check_plausibility
from gmloco.train.tasks.g1_jump.profile import GRAVITY, JumpProfileCfg, make_jump_profile, quintic
from gmloco.train.tasks.g1_jump.reference import REFERENCE_DIR, JumpReference, load_reference, reference_path

NAMES = ("vertical", "forward")
"""Shipped references."""


@pytest.fixture(scope="module")
def model() -> object:
    """The G1 model the references were built on."""
    return load_g1_model()


@pytest.fixture(scope="module", params=NAMES)
def shipped(request: pytest.FixtureRequest, model: object) -> tuple[JumpReference, PlausibilityReport]:
    """A shipped reference and its plausibility report."""
    ref = load_reference(reference_path(request.param))
    return ref, check_plausibility(model, ref)  # type: ignore[arg-type]


def test_quintic_meets_its_boundary_conditions() -> None:
    """The quintic starts at (p, v, a) = (1, 2, 3) and ends at (-1, 0.5, -9.81) after 0.3 s."""
    out = quintic(np.array([0.0, 0.3]), 0.3, (1.0, 2.0, 3.0), (-1.0, 0.5, -9.81))
    np.testing.assert_allclose(out[:, 0], [1.0, 2.0, 3.0], atol=1e-9)
    np.testing.assert_allclose(out[:, 1], [-1.0, 0.5, -9.81], atol=1e-9)


def test_profile_flight_is_ballistic_and_lands_at_take_off_height() -> None:
    """Flight lasts 2 v0 / g with v0 = sqrt(2 g h); the apex is h above take-off, z'' = -g throughout."""
    cfg = JumpProfileCfg(apex_rise=0.08, takeoff_rise=-0.04)
    p = make_jump_profile(cfg)
    v0 = np.sqrt(2.0 * GRAVITY * cfg.apex_rise)  # 1.2528 m/s
    np.testing.assert_allclose(p.t_touchdown - p.t_takeoff, 2.0 * v0 / GRAVITY, atol=1e-12)
    flight = ~p.in_contact
    np.testing.assert_allclose(p.com_acc[flight, 2], -GRAVITY, atol=1e-12)
    np.testing.assert_allclose(p.com[flight, 2].max(), cfg.takeoff_rise + cfg.apex_rise, atol=v0**2 / GRAVITY / 100)
    # Ground force F_z = m (z'' + g) is unilateral throughout the stance phases.
    assert (p.com_acc[p.in_contact, 2] + GRAVITY).min() > -1e-9


def test_forward_profile_travels_the_jump_distance() -> None:
    """The CoM and the feet both end ``distance`` ahead; CoM x'' is zero in flight."""
    p = make_jump_profile(JumpProfileCfg(distance=0.2, takeoff_rise=-0.06))
    np.testing.assert_allclose(p.com[-1, 0], 0.2, atol=1e-9)
    np.testing.assert_allclose(p.foot_offset[-1], [0.2, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(p.com_acc[~p.in_contact, 0], 0.0, atol=1e-12)


def test_bad_profile_is_refused() -> None:
    """A non-positive jump height is a clear error."""
    with pytest.raises(ValueError, match="apex_rise"):
        make_jump_profile(JumpProfileCfg(apex_rise=0.0))


def test_flight_com_is_ballistic(shipped: tuple[JumpReference, PlausibilityReport]) -> None:
    """The whole-body CoM accelerates at (0, 0, -g) in flight.

    Second differences of a parabola are exact, so the error is the IK residual (<= tolerance) over dt^2, times 4.
    """
    ref, report = shipped
    tol = 4.0 * IkCfg().tolerance * ref.fps**2 + 1e-9
    assert report.flight_com_acc_error < tol
    # The unactuated base force in flight is m (a_com + g) = 0 up to the truncation error of the joint-space second
    # differences (O(dt^2) jerk terms at 100 Hz): bounded at 2 % of the weight.
    assert report.flight_base_force < 0.02 * report.mass * GRAVITY


def test_flight_angular_momentum_is_zero(model: object, shipped: tuple[JumpReference, PlausibilityReport]) -> None:
    """Over every flight step the whole-body angular momentum about the CoM is zero (the IK's momentum task).

    The IK stops when the momentum error times dt / m is below its tolerance, so |L| <= tolerance m fps.
    """
    from gmloco.train.tasks.g1_jump.ik import WholeBodyIk

    ref, report = shipped
    ik = WholeBodyIk(model, IkCfg())  # type: ignore[arg-type]
    steps = np.flatnonzero(~ref.in_contact[1:] & ~ref.in_contact[:-1]) + 1
    L = np.array([ik.step_momentum(ref.qpos[i - 1], ref.qpos[i], 1.0 / ref.fps) for i in steps])
    assert L.shape[0] > 10
    np.testing.assert_allclose(L, 0.0, atol=IkCfg().tolerance * report.mass * ref.fps)


def test_feet_kinematics(shipped: tuple[JumpReference, PlausibilityReport]) -> None:
    """Stance soles stay flat on the ground and still; flight soles stay above it."""
    ref, report = shipped
    assert report.stance_foot_height_error < 1e-6
    assert report.stance_foot_speed < 1e-6 * ref.fps
    assert report.flight_min_foot_clearance > -1e-6
    assert ref.in_contact[0] and ref.in_contact[-1] and not ref.in_contact.all()


def test_ground_force_is_unilateral_and_inside_the_friction_cone(
    shipped: tuple[JumpReference, PlausibilityReport],
) -> None:
    """Stance normal force >= 0, |F_xy| / F_z below a sand-like 0.6, CoP under the soles."""
    _, report = shipped
    assert report.min_normal_force > 0.0
    assert report.max_friction_ratio < 0.6
    assert report.max_cop_excursion < 1.0


def test_joint_position_and_velocity_limits(shipped: tuple[JumpReference, PlausibilityReport]) -> None:
    """Every joint stays inside its range and below its motor velocity limit."""
    _, report = shipped
    assert report.joint_limit_margin > 0.0
    assert report.max_velocity_ratio < 1.0


def test_torques_within_effort_limits(shipped: tuple[JumpReference, PlausibilityReport]) -> None:
    """Every joint's torque (legs, waist, arms, wrists) stays within the G1's effort limit."""
    _, report = shipped
    ratio = {n: t / report.effort_limit[n] for n, t in report.peak_torque.items()}
    assert len(ratio) == 29
    assert max(ratio.values()) < 1.0, {n: r for n, r in ratio.items() if r >= 1.0}


def test_flight_has_no_external_moment(shipped: tuple[JumpReference, PlausibilityReport]) -> None:
    """In flight the unactuated base torque (the rate of change of the angular momentum) is near zero.

    The momentum is held constant over each step (midpoint rule); the residual is the truncation error of the
    joint-space second differences, bounded like the base force at 2 % of the weight times a 0.1 m lever.
    """
    _, report = shipped
    assert report.flight_base_torque < 0.02 * report.mass * GRAVITY * 0.1


def test_standing_torques_match_the_weight(model: object) -> None:
    """At rest the soles carry exactly m g (mj_inverse statics), split (almost) equally between the feet."""
    ref = load_reference(reference_path("vertical"))
    from gmloco.train.tasks.g1_jump.plausibility import inverse_dynamics

    wrench, _, _ = inverse_dynamics(model, ref)  # type: ignore[arg-type]
    mass = float(model.body_subtreemass[1])  # type: ignore[attr-defined]
    np.testing.assert_allclose(wrench[5, :, 2].sum(), mass * GRAVITY, rtol=1e-6)
    # The G1's CoM sits 0.08 mm off its sagittal plane, so the two soles differ by ~2e-5 of their load.
    np.testing.assert_allclose(wrench[5, 0, 2], wrench[5, 1, 2], rtol=1e-4)


def test_manifest_describes_the_files(model: object) -> None:
    """manifest.json names each file, the command that made it and the effort limits of every joint."""
    manifest = json.loads((REFERENCE_DIR / "manifest.json").read_text())
    assert manifest["command"] == "python -m gmloco.train.tasks.g1_jump.make_reference"
    effort, velocity = g1_joint_limits(model)  # type: ignore[arg-type]
    for name in NAMES:
        entry = manifest["references"][name]
        assert (REFERENCE_DIR / entry["file"]).stat().st_size < 200_000
        assert sorted(entry["plausibility"]["effort_limit"].values()) == sorted(effort.tolist())
    assert (velocity > 0).all()


def test_missing_reference_says_how_to_make_it(tmp_path: object) -> None:
    """Loading a file that is not there names the command that writes it."""
    with pytest.raises(FileNotFoundError, match="make_reference"):
        load_reference(f"{tmp_path}/nope.npz")
