# SPDX-License-Identifier: Apache-2.0
"""The candidate-effect vocabulary: stable ids, parameters with units and bounds, signatures, confusables.

Each effect is a parametric change of the nominal simulator (:mod:`gmloco.deploy.mismatch.g1model`) that is
*exactly* nominal at zero parameters. The ids are part of the report schema and never change meaning;
new effects get new ids. Physics and signatures follow ``shared/reference/mismatch-discovery.md`` section 2.
The code that realises each effect lives in :mod:`gmloco.deploy.mismatch.replay` (actuator, sensor, model
edits) and :mod:`gmloco.deploy.mismatch.terrain` (ground); the ranking code never special-cases an id.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from gmloco.deploy.logs.g1 import G1_JOINT_NAMES

__all__ = [
    "BACKLASH_GROUPS",
    "EFFECTS",
    "EFFECT_IDS",
    "LEG_JOINTS",
    "LIMB_LINKS",
    "OUTCOME_IDS",
    "EffectSpec",
    "ParamSpec",
    "check_effect_ids",
    "effect",
    "params_from_patch",
    "zero_params",
]

LEG_JOINTS: tuple[str, ...] = G1_JOINT_NAMES[:12]
"""Joints carrying per-joint effect parameters (encoder offsets): the two legs, hip to ankle."""

LIMB_LINKS: tuple[str, ...] = ("left_hip_yaw_link", "right_hip_yaw_link", "left_knee_link", "right_knee_link")
"""Bodies carrying limb-mass parameters: the thighs (hip-yaw links) and shanks (knee links)."""

BACKLASH_GROUPS: tuple[str, ...] = ("hip", "knee", "ankle")
"""Leg-joint groups sharing one backlash width (both legs)."""

OUTCOME_IDS: tuple[str, ...] = ("none", "unexplained")
"""Report outcomes that are not effects: nothing missing, or something outside the library."""


@dataclass(frozen=True)
class ParamSpec:
    """One (possibly vector) parameter of an effect; zero is the nominal simulator."""

    name: str
    """Parameter name, unique within the effect."""
    unit: str
    """SI unit, ``"1"`` when dimensionless."""
    size: int
    """Number of components (e.g. 12 encoder offsets, 3 gyro biases)."""
    lower: float
    """Lower bound of every component."""
    upper: float
    """Upper bound of every component."""
    fd_step: float
    """Finite-difference step used for sensitivities, same unit."""
    tolerance: float
    """Smallest magnitude that counts as a mismatch (a practical, not statistical, threshold), same unit."""
    doc: str
    """What the parameter means."""
    labels: tuple[str, ...] = ()
    """Component labels (joint or axis names) when ``size > 1``."""


@dataclass(frozen=True)
class EffectSpec:
    """A candidate missing physics."""

    id: str
    """Stable effect id (``<group>.<name>``)."""
    title: str
    """Human-readable name."""
    params: tuple[ParamSpec, ...]
    """Parameters; all zero is the nominal simulator."""
    model: str
    """Parametric model, in words and equations."""
    signature: str
    """Where it shows in proprioceptive data (signal, phase)."""
    phases: tuple[str, ...]
    """Gait phases where it can act (``swing``, ``touchdown``, ``stance``, ``liftoff``, ``any``)."""
    signals: tuple[str, ...]
    """Signals it changes (``q``, ``dq``, ``tau_est``, ``gyro``, ``acc``, ``gyro_att``)."""
    confusables: tuple[str, ...]
    """Effect ids with similar signatures."""
    excitation: str
    """What a recording needs for the effect to be testable."""
    ground: bool = False
    """Whether it acts only through ground contact: on a held pelvis (gantry, fixed), whose replay touches
    nothing, its sensitivity is exactly zero and screening skips its replays."""

    @property
    def size(self) -> int:
        """Total number of parameter components."""
        return sum(p.size for p in self.params)

    def split(self, theta: np.ndarray) -> dict[str, np.ndarray]:
        """Split a flat parameter vector into named parameters."""
        out, i = {}, 0
        for p in self.params:
            out[p.name] = np.asarray(theta[i : i + p.size], dtype=float)
            i += p.size
        return out

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Return flat lower and upper bounds, shape [size] each."""
        lo = np.concatenate([np.full(p.size, p.lower) for p in self.params])
        hi = np.concatenate([np.full(p.size, p.upper) for p in self.params])
        return lo, hi

    def flat(self, attr: str) -> np.ndarray:
        """Return a per-component vector of a :class:`ParamSpec` attribute (``fd_step``, ``tolerance``)."""
        return np.concatenate([np.full(p.size, getattr(p, attr)) for p in self.params])

    def labels(self) -> list[str]:
        """Return flat component labels ``name`` or ``name[label]``."""
        out = []
        for p in self.params:
            out += [p.name] if p.size == 1 else [f"{p.name}[{lab}]" for lab in (p.labels or map(str, range(p.size)))]
        return out


_A = ("q", "dq", "tau_est", "gyro", "acc")
EFFECTS: tuple[EffectSpec, ...] = (
    EffectSpec(
        "actuator.delay",
        "Action / command delay",
        (ParamSpec("delay", "s", 1, 0.0, 0.04, 0.002, 0.002, "Transport delay of every LowCmd field."),),
        "u(t) = u_cmd(t - d), linear interpolation of the logged commands (Isaac Lab DelayedPDActuator).",
        "Residual ~ -d du/dt; phase lag of q behind q_cmd growing with frequency; same on all joints.",
        ("any",),
        ("q", "dq", "tau_est"),
        ("actuator.gain_scale", "joint.armature"),
        "Commands that change faster than the delay (swing, stepping, chirps).",
    ),
    EffectSpec(
        "actuator.gain_scale",
        "PD gain mismatch",
        (ParamSpec("kp_scale", "1", 1, -0.6, 0.6, 0.03, 0.06, "Realised gains (1 + s) kp, (1 + s) kd."),),
        "tau = (1 + s) (kp (q* - q) + kd (dq* - dq)) + tau_ff; tau_est reports the realised torque.",
        "tau_est differs from the PD law evaluated on logged q; stance sag; altered swing overshoot.",
        ("any",),
        _A,
        ("joint.viscous_damping", "actuator.torque_speed"),
        "Non-zero tracking error (any load).",
    ),
    EffectSpec(
        "actuator.torque_speed",
        "Torque-speed saturation (DC-motor envelope)",
        (ParamSpec("droop", "s/rad", 1, 0.0, 0.5, 0.01, 0.01, "Torque limit lost per rad/s of joint speed."),),
        "|tau| <= tau_max (1 - droop |dq|) (Isaac Lab DCMotor envelope); tau_max from mjlab's G1 constants.",
        "tau_est plateaus while the PD torque grows: push-off, fast swing, deep stance.",
        ("stance", "liftoff", "swing"),
        _A,
        ("actuator.gain_scale", "terrain.depth_hardening"),
        "Torques near the limit at high joint speed (push-off, fast swings).",
    ),
    EffectSpec(
        "joint.coulomb_friction",
        "Coulomb joint friction",
        (
            ParamSpec(
                "tau_c", "N*m", 1, 0.0, 8.0, 0.3, 0.3, "Friction of an 88 N*m joint; others scale by effort limit."
            ),
        ),
        "Dry friction of magnitude tau_c * tau_max_j / 88 N*m (MuJoCo frictionloss constraint).",
        "Steps in the motion residual at dq sign changes; position error ~ tau_c / kp at low speed.",
        ("swing", "any"),
        ("q", "dq", "gyro", "acc"),
        ("joint.viscous_damping", "sensor.encoder_offset"),
        "Joint velocity reversals (swing, stepping, chirps).",
    ),
    EffectSpec(
        "joint.viscous_damping",
        "Viscous joint damping",
        (
            ParamSpec(
                "b", "N*m*s/rad", 1, -0.5, 6.0, 0.15, 0.15, "Damping of an 88 N*m joint; others scale by effort limit."
            ),
        ),
        "tau_f = -b_j dq with b_j = b tau_max_j / 88 N*m. With dq* = 0 it is collinear with kd in motion, "
        "but not in tau_est, which only sees the PD torque.",
        "Motion residual ~ dq, phase lag at high swing speed; tau_est unchanged.",
        ("swing", "any"),
        ("q", "dq", "gyro", "acc"),
        ("actuator.gain_scale", "joint.coulomb_friction", "joint.armature"),
        "Joint speeds well above the encoder noise.",
    ),
    EffectSpec(
        "joint.armature",
        "Armature (reflected rotor inertia)",
        (ParamSpec("scale", "1", 1, -0.8, 6.0, 0.3, 0.25, "Armature (1 + s) times mjlab's nominal."),),
        "(M(q) + diag((1 + s) I_a)) ddq.",
        "Residual ~ ddq: swing reversals, touchdown; shifts the PD natural frequency.",
        ("swing", "touchdown", "any"),
        ("q", "dq", "tau_est", "gyro", "acc"),
        ("actuator.delay", "terrain.rate_drag"),
        "Joint accelerations (swing, reversals).",
    ),
    EffectSpec(
        "sensor.encoder_offset",
        "Encoder offset / calibration bias",
        (ParamSpec("offset", "rad", 12, -0.1, 0.1, 0.005, 0.006, "q_meas = q + offset, leg joints.", LEG_JOINTS),),
        "q_meas = q_true + c_j on the leg joints; the motor PD acts on q_meas.",
        "Constant posture and gravity-torque bias per joint, phase independent.",
        ("any",),
        ("q", "dq", "tau_est", "gyro", "acc"),
        ("imu.misalignment",),
        "Any loaded posture (standing is enough).",
    ),
    EffectSpec(
        "imu.gyro_bias",
        "Gyroscope bias",
        (ParamSpec("bias", "rad/s", 3, -0.2, 0.2, 0.01, 0.006, "Additive gyro bias.", ("x", "y", "z")),),
        "gyro_meas = omega + b (IMU frame).",
        "Constant gyro offset in every phase; the gyro disagrees with the rate of the logged attitude (gyro_att).",
        ("any",),
        ("gyro", "gyro_att"),
        ("imu.misalignment",),
        "Any recording.",
    ),
    EffectSpec(
        "imu.misalignment",
        "IMU mounting misalignment",
        (
            ParamSpec(
                "angle",
                "rad",
                2,
                -0.15,
                0.15,
                0.01,
                0.01,
                "IMU roll and pitch relative to the pelvis.",
                ("roll", "pitch"),
            ),
        ),
        "R_imu = R_pelvis R_x(roll) R_y(pitch): quaternion, gyro and accelerometer rotated.",
        "Base tilt inconsistent with flat feet: stance torques, tilting motion after reset.",
        ("stance", "any"),
        ("q", "dq", "tau_est", "gyro", "acc"),
        ("sensor.encoder_offset", "imu.gyro_bias"),
        "Standing or stepping with the feet on level ground.",
    ),
    EffectSpec(
        "body.mass_error",
        "Body mass error (torso payload)",
        (ParamSpec("delta_mass", "kg", 1, -5.0, 12.0, 0.5, 0.6, "Mass added at the torso-link centre of mass."),),
        "m_torso += dm, inertia scaled with mass.",
        "Stance torque bias (hips, knees), sag ~ dm g / kp.",
        ("stance",),
        ("q", "dq", "tau_est", "gyro", "acc"),
        ("actuator.gain_scale", "terrain.stiffness_scale"),
        "Standing or stance phases.",
    ),
    EffectSpec(
        "actuator.torque_limit",
        "Static torque limit",
        (
            ParamSpec(
                "limit_loss",
                "1",
                1,
                0.0,
                0.9,
                0.3,
                0.05,
                "Fraction of the nominal effort limit the motor cannot deliver, at any speed.",
            ),
        ),
        "|tau| <= (1 - s) tau_max (1 - droop |dq|): a lower peak torque (driver current limit, supply voltage), "
        "beside the speed droop of actuator.torque_speed. A threshold effect: zero sensitivity where torques stay "
        "below (1 - s) tau_max, so the finite-difference probe is large (30 %).",
        "tau_est flat-topped at the same level at every speed; tracking error grows only while the PD torque is high.",
        ("stance", "liftoff", "swing", "any"),
        _A,
        ("actuator.torque_speed", "actuator.gain_scale"),
        "PD torques above ~70 % of the effort limit (push-off, deep squats, fast chirps).",
    ),
    EffectSpec(
        "joint.coulomb_friction_leg",
        "Per-joint Coulomb friction (legs)",
        (ParamSpec("tau_c", "N*m", 12, 0.0, 6.0, 0.3, 0.3, "Dry friction of each leg joint, not scaled.", LEG_JOINTS),),
        "Dry friction tau_c_j on each leg joint (MuJoCo frictionloss), added to joint.coulomb_friction's profile.",
        "Steps in the motion residual of one joint at its velocity reversals.",
        ("swing", "any"),
        ("q", "dq", "gyro", "acc"),
        ("joint.coulomb_friction", "joint.viscous_damping_leg", "actuator.backlash"),
        "Velocity reversals of every leg joint (chirps, stepping).",
    ),
    EffectSpec(
        "joint.viscous_damping_leg",
        "Per-joint viscous damping (legs)",
        (ParamSpec("b", "N*m*s/rad", 12, -0.5, 4.0, 0.15, 0.15, "Damping of each leg joint, not scaled.", LEG_JOINTS),),
        "tau_f,j = -b_j dq_j on each leg joint (MuJoCo dof_damping), added to joint.viscous_damping's profile.",
        "Motion residual ~ dq of one joint; tau_est unchanged.",
        ("swing", "any"),
        ("q", "dq", "gyro", "acc"),
        ("joint.viscous_damping", "joint.coulomb_friction_leg"),
        "Speeds of every leg joint well above the encoder noise (chirps, swing).",
    ),
    EffectSpec(
        "actuator.backlash",
        "Gear backlash / position dead zone",
        (
            ParamSpec(
                "width",
                "rad",
                3,
                0.0,
                0.06,
                0.006,
                0.006,
                "Dead-band width of the position loop, per leg-joint group (both legs).",
                BACKLASH_GROUPS,
            ),
        ),
        "The motor PD sees the position error through a dead band: e' = e - clip(e, -w/2, w/2) (lost motion of "
        "the gear as the motor controller sees it).",
        "Tracking error up to w/2 that the PD does not correct; softer joints at small amplitude, flat tau_est there.",
        ("swing", "stance", "any"),
        _A,
        ("actuator.gain_scale", "joint.coulomb_friction_leg"),
        "Small and large tracking errors on the leg joints (chirps, standing sway).",
    ),
    EffectSpec(
        "body.limb_mass",
        "Limb mass error",
        (
            ParamSpec(
                "delta_mass",
                "kg",
                4,
                -1.0,
                3.0,
                0.3,
                0.3,
                "Mass added at the centre of mass of each thigh and shank.",
                ("left_thigh", "right_thigh", "left_shank", "right_shank"),
            ),
        ),
        "m_link += dm at the link's centre of mass, inertia scaled with mass (thighs: hip-yaw links, shanks: knee "
        "links).",
        "Gravity and inertia torques of one leg: swing-leg tracking, stance hip/knee torques, chirp amplitude.",
        ("swing", "stance", "any"),
        _A,
        ("body.mass_error", "joint.armature"),
        "Leg swings or chirps (inertia), any loaded posture (gravity).",
    ),
    EffectSpec(
        "terrain.stiffness_scale",
        "Ground stiffness / packing scale (zeta)",
        (ParamSpec("zeta", "1", 1, -0.9, 8.0, 0.3, 0.3, "Added depth-linear stress zeta * alpha_ref * z."),),
        "sigma_z += zeta alpha_ref z at each sole point (RFT depth-linear law, Li, Zhang & Goldman 2013).",
        "Uniform change of stance sinkage and stance ankle/knee motion.",
        ("stance", "touchdown"),
        ("q", "dq", "tau_est", "acc"),
        ("body.mass_error", "terrain.depth_hardening"),
        "Stance phases; sinkage itself needs external sensing.",
        ground=True,
    ),
    EffectSpec(
        "terrain.depth_hardening",
        "Non-linear depth hardening",
        (ParamSpec("kappa", "1/m", 1, 0.0, 3000.0, 100.0, 100.0, "Added stress alpha_ref kappa z^2."),),
        "sigma_z += alpha_ref kappa z^2 (Bekker-type convexity).",
        "Deep-sinkage steps stiffer than shallow ones; confusable with zeta when the depth range is narrow.",
        ("stance", "touchdown"),
        ("q", "dq", "tau_est", "acc"),
        ("terrain.stiffness_scale",),
        "A range of sinkage depths (varying load).",
        ground=True,
    ),
    EffectSpec(
        "terrain.rate_drag",
        "Rate-dependent (inertial) drag",
        (ParamSpec("rho_drag", "kg/m^3", 1, 0.0, 2.0e5, 4000.0, 4000.0, "Drag rho A v_z^2 on intruding points."),),
        "F_z += rho_drag A_i v_z^2 while the point intrudes (Roth, Han & Jaeger, arXiv 1910.10358).",
        "Early-stance / touchdown deceleration, rises with impact speed.",
        ("touchdown",),
        ("q", "dq", "tau_est", "acc"),
        ("joint.armature",),
        "Touchdowns at varied speeds.",
        ground=True,
    ),
    EffectSpec(
        "terrain.cohesion",
        "Cohesion / suction",
        (ParamSpec("cohesion", "Pa", 1, 0.0, 4.0e4, 500.0, 500.0, "Adhesion stress on sole points in contact."),),
        "F_z -= c A_i at sole points below the surface (Mohr-Coulomb cohesion, wet-sand RFT).",
        "Delayed lift-off, extra flexion torque at LO, lower stance sinkage.",
        ("liftoff", "stance"),
        ("q", "dq", "tau_est", "acc"),
        ("terrain.stiffness_scale", "body.mass_error"),
        "Lift-offs (stepping).",
        ground=True,
    ),
)
"""The library, in report order."""

EFFECT_IDS: tuple[str, ...] = tuple(e.id for e in EFFECTS)
"""Stable effect ids."""


def effect(effect_id: str) -> EffectSpec:
    """Return the spec of an effect id.

    Raises:
        KeyError: Unknown id; the message lists the vocabulary.
    """
    for e in EFFECTS:
        if e.id == effect_id:
            return e
    raise KeyError(f"unknown effect id {effect_id!r}; vocabulary: {EFFECT_IDS}")


def check_effect_ids(ids: Iterable[str]) -> tuple[str, ...]:
    """Return ``ids`` as a tuple after checking each against the library.

    Raises:
        ValueError: An id is not in :data:`EFFECT_IDS`; one paragraph names it, the closest ids and the library.
    """
    ids = tuple(ids)
    unknown = [i for i in ids if i not in EFFECT_IDS]
    if not unknown:
        return ids
    hints = [
        f"'{u}' (did you mean '{c[0]}'?)" if (c := difflib.get_close_matches(u, EFFECT_IDS, 1)) else f"'{u}'"
        for u in unknown
    ]
    raise ValueError(
        f"unknown effect id {', '.join(hints)}: an effect that is not in the library would be screened by nothing "
        f"and the verdict would say nothing about it. Effect ids: {', '.join(EFFECT_IDS)}."
    )


def params_from_patch(patch: dict[str, dict[str, float]]) -> dict[str, np.ndarray]:
    """Turn a report's ``config_patch`` (``{effect_id: {label: value}}``) into the replay's flat parameters.

    Labels are :meth:`EffectSpec.labels` (``name`` or ``name[component]``); missing components stay nominal (0).

    Raises:
        KeyError: Unknown effect id or label.
    """
    out = {}
    for eid, values in patch.items():
        spec = effect(eid)
        labels = spec.labels()
        theta = np.zeros(spec.size)
        for lab, v in values.items():
            if lab not in labels:
                raise KeyError(f"effect {eid!r} has no parameter {lab!r}; labels: {labels}")
            theta[labels.index(lab)] = float(v)
        out[eid] = theta
    return out


def zero_params() -> dict[str, np.ndarray]:
    """Return all-zero (nominal) flat parameter vectors for every effect."""
    return {e.id: np.zeros(e.size) for e in EFFECTS}
