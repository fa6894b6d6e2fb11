# SPDX-License-Identifier: Apache-2.0
"""The identification protocol: which recording stage excites which effect.

A recording that cannot excite an effect (screening: a tolerance-sized change stays below the noise floor, or a
held pelvis for a ground effect) gets "untestable here: record stage X" in the report, X being the first stage
of the effect's list that the recording is not. Every stage has a controller the project ships:
``python -m gmloco.deploy.mismatch.benchmark.make_recording --stage X`` (``shared/reference/mismatch-discovery.md``
section 3.3: an in-air chirp stage, then standing, stepping in place, walking at several speeds and turning).
"""

from __future__ import annotations

from typing import Literal

from gmloco.deploy.mismatch.recording import Recording

__all__ = ["STAGES", "Stage", "effect_stages", "recording_stage", "stage_to_record"]

Stage = Literal["chirp", "stand", "step", "walk", "turn"]
"""A protocol stage."""

STAGES: dict[str, str] = {
    "chirp": "pelvis held on a gantry, PD-tracked chirps 0.5-6 Hz on the leg and waist joints",
    "stand": "standing on level ground with arm and waist motion",
    "step": "stepping in place on level ground",
    "walk": "walking at several speeds (0.5, 1.0, 1.5 m/s) under the walking policy",
    "turn": "walking while turning (0.8 m/s, 0.5 rad/s yaw) under the walking policy",
}
"""Protocol stages and what each records."""

_EFFECT_STAGES: dict[str, tuple[Stage, ...]] = {
    "actuator.delay": ("chirp", "step"),
    "actuator.gain_scale": ("chirp", "stand", "step"),
    "actuator.torque_speed": ("walk",),
    "joint.coulomb_friction": ("chirp", "step"),
    "joint.viscous_damping": ("chirp", "walk"),
    "joint.armature": ("chirp", "step"),
    "sensor.encoder_offset": ("stand", "chirp"),
    "imu.gyro_bias": ("stand", "turn"),
    "imu.misalignment": ("stand", "turn"),
    "body.mass_error": ("stand", "step"),
    "actuator.torque_limit": ("walk", "chirp"),
    "joint.coulomb_friction_leg": ("chirp", "step"),
    "joint.viscous_damping_leg": ("chirp", "walk"),
    "actuator.backlash": ("chirp", "stand"),
    "body.limb_mass": ("chirp", "stand"),
    "terrain.stiffness_scale": ("stand", "step"),
    "terrain.depth_hardening": ("walk", "step"),
    "terrain.rate_drag": ("walk",),
    "terrain.cohesion": ("step", "walk"),
}
"""Stages that excite each effect, best first (from each effect's ``excitation``: chirps excite the joint-level
effects in isolation; standing the static ones; stepping the touchdowns and lift-offs; walking at speed the torque
envelope and varied impacts; turning the yaw rate that a mounting rotation mixes into the other gyro axes)."""

_CONTROLLER_STAGE: dict[str, Stage] = {
    "scripted_chirp": "chirp",
    "scripted_stand": "stand",
    "scripted_step": "step",
    "scripted_walk": "walk",
    "stage_chirp": "chirp",
    "stage_stand": "stand",
    "stage_step": "step",
    "stage_walk": "walk",
    "stage_turn": "turn",
}
"""Stage of a recording by its run metadata ``controller`` (the project's own controllers)."""


def effect_stages(effect_id: str) -> tuple[Stage, ...]:
    """Stages that excite ``effect_id``, best first.

    Raises:
        KeyError: an effect the protocol does not map (every library effect is mapped; tested).
    """
    return _EFFECT_STAGES[effect_id]


def recording_stage(rec: Recording) -> Stage | None:
    """The stage a recording is, if known: a held pelvis is the chirp stage, else the controller label says."""
    if rec.fixed_base:
        return "chirp"
    label = rec.meta.get("controller", "")
    return _CONTROLLER_STAGE.get(label.split(":")[0].strip())


def stage_to_record(effect_id: str, done: set[str] | frozenset[str] = frozenset()) -> Stage:
    """The first stage that excites ``effect_id`` among those not in ``done`` (the stages already recorded).

    When every stage of the effect is already recorded, its best stage again: a longer or stronger recording
    of it is what is missing.
    """
    stages = effect_stages(effect_id)
    for s in stages:
        if s not in done:
            return s
    return stages[0]
