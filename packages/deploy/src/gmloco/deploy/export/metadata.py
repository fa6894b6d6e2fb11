# SPDX-License-Identifier: Apache-2.0
"""Deploy metadata of an exported policy: one versioned JSON document in the ONNX ``metadata_props`` (onnx only).

Everything a runner needs that is not in the network is here: the observation terms in order with their
widths, clip and scale, the history length and order, the input layout, the joints with PD gains, default pose,
action scale and effort limits, physics and policy periods, the contact model with its foot collider, the terrain,
materials and robot randomization trained on, and the command ranges with the heading rule. The document sits under one key
(:data:`METADATA_KEY`); its ``schema`` / ``schema_version`` fields say how to read it, and a reader refuses a
file without it or with a version it does not know (:class:`PolicyMetadataError`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any, Literal

import onnx

__all__ = [
    "METADATA_KEY",
    "SCHEMA_NAME",
    "SCHEMA_VERSION",
    "YAW_COMMANDS",
    "CommandSpec",
    "ContactSpec",
    "FootColliderSpec",
    "JointSpec",
    "ObservationSpec",
    "ObservationTermSpec",
    "PolicyMetadata",
    "PolicyMetadataError",
    "TimingSpec",
    "read_policy_metadata",
    "write_policy_metadata",
]

SCHEMA_NAME = "gmloco-policy"
"""Value of the document's ``schema`` field."""
SCHEMA_VERSION = 2
"""Version of the document this code writes and reads; bump when a field is added or changes meaning."""
METADATA_KEY = "gmloco_policy"
"""ONNX ``metadata_props`` key holding the JSON document."""
_LEGACY_FORMAT_KEY = "format"
"""Key of the version-1 student metadata (one JSON value per field), which lacks contact, timing and commands."""

YAW_COMMANDS = ("yaw_target", "heading_envs")
"""Heading rules a policy can be trained with (:attr:`CommandSpec.yaw_command`)."""

InputLayout = Literal["frame_and_history", "term_stacked"]
"""How observation frames reach the network (see :class:`ObservationSpec`)."""


class PolicyMetadataError(ValueError):
    """The file carries no gmloco policy metadata, an unknown schema version, or an inconsistent document."""


@dataclass
class ObservationTermSpec:
    """One term of the observation frame o_t."""

    name: str
    """Term name (mjlab observation term), e.g. ``"base_ang_vel"``."""
    dim: int
    """Width of the term in one frame."""
    scale: float | list[float] = 1.0
    """Multiplier applied after the clip (scalar or one per element)."""
    clip: list[float] | None = None
    """``[low, high]`` applied to the raw (noise-free at deploy) value before the scale; None: no clip."""
    description: str = ""
    """What the term is, in which frame and order, with SI units."""


@dataclass
class ObservationSpec:
    """Observation frame layout and history convention.

    One frame o_t is the concatenation of the terms in order, each computed raw, clipped, then scaled. The history
    holds the last ``history_length`` frames ``o_{t-N+1} .. o_t``, oldest first, the current frame last. Layouts:
    ``"frame_and_history"``: inputs ``obs`` ``[batch, obs_dim]`` (o_t) and ``history`` ``[batch, N, obs_dim]``;
    ``"term_stacked"``: one input ``[batch, N * obs_dim]``, for each term in order its N frames oldest first
    (mjlab's flattened per-term history).
    """

    terms: list[ObservationTermSpec]
    """Terms of one frame, in order."""
    history_length: int
    """N, frames kept (1: the current frame only)."""
    layout: InputLayout
    """How the frames are fed to the network."""
    history_order: Literal["oldest_first"] = "oldest_first"
    """Frame order along the history axis: ``o_{t-N+1}`` first, o_t last."""
    history_padding: Literal["repeat_first", "zeros"] = "repeat_first"
    """Fill of the older frames on the first step after a reset: repeat that first frame (mjlab) or zeros."""

    @property
    def obs_dim(self) -> int:
        """Width of one frame o_t."""
        return sum(t.dim for t in self.terms)


@dataclass
class JointSpec:
    """Actuated joints, all lists in action order; joint target q* = default_pos + action_scale * action."""

    names: list[str]
    """Joint names in action order (also the order of the joint terms of o_t)."""
    stiffness: list[float]
    """PD stiffness kp [N m/rad]."""
    damping: list[float]
    """PD damping kd [N m s/rad]."""
    default_pos: list[float]
    """Nominal pose q_0 [rad]."""
    action_scale: list[float]
    """Joint-position offset per unit action [rad]."""
    effort_limit: list[float]
    """Actuator torque limit |tau| <= effort_limit [N m] (the PD torque is clipped to it in training)."""


@dataclass
class TimingSpec:
    """Simulation and control periods."""

    physics_dt: float
    """Physics step [s]."""
    decimation: int
    """Physics steps per policy step; the PD targets are held over them."""
    policy_dt: float
    """Policy period [s] = physics_dt * decimation."""


@dataclass
class FootColliderSpec:
    """Foot box the granular contact model samples, in each foot body's frame."""

    body_names: list[str]
    """Foot bodies carrying the box (left, right)."""
    x_range: list[float]
    """Box extent along body x [m] (min, max)."""
    y_range: list[float]
    """Box extent along body y [m] (min, max)."""
    z_range: list[float]
    """Box extent along body z [m] (min, max); the sole is the face at z_range[0]."""
    faces: Literal["sole", "box"]
    """Faces sampled: the -z face (``"sole"``) or all six (``"box"``)."""
    resolution: list[int]
    """Cells along (x, y, z) of the sampled faces."""


@dataclass
class ContactSpec:
    """Foot-ground contact model and the ground it was trained on."""

    model: str
    """Contact model name (``rft3d``, ``heuristic_rft``, ``cone_multi``, ``cone_single``, ``rigid``)."""
    foot_collider: FootColliderSpec
    """Foot collider of the model (cone models use its sole centre and hydraulic radius only)."""
    contact_force_threshold: float
    """|F| above which a foot counts as in contact [N]."""
    terrain: dict[str, Any]
    """Sand surface and floor (the training config's ``SandTerrainCfg`` fields, SI units)."""
    materials: dict[str, Any]
    """Granular material ranges drawn per episode (the training config's ``MaterialRangeCfg`` fields)."""
    robot_randomization: dict[str, Any]
    """Robot domain randomization trained with (the training config's ``RobotDrCfg`` fields)."""


@dataclass
class CommandSpec:
    """Velocity command of the ``command`` observation term."""

    name: str
    """Command term name."""
    lin_vel_x: list[float]
    """Initial range of the forward velocity command [m/s]."""
    lin_vel_y: list[float]
    """Range of the lateral velocity command [m/s]."""
    ang_vel_z: list[float]
    """Initial range of the yaw-rate command [rad/s]."""
    yaw_command: str
    """Heading rule trained with. ``"yaw_target"``: a yaw target integrates the commanded w_z every policy step
    (re-snapped to the heading when the error passes pi/2) and the observed yaw rate is
    ``w_z_obs = clip(w_z + heading_stiffness * wrap(yaw_target - yaw), ang_vel_z range)``, so a runner must apply
    the same correction; ``"heading_envs"``: mjlab's heading envs (a share of the envs steered toward a random
    heading with ``heading_stiffness``, the rest commanded w_z directly), so a runner may command w_z directly."""
    heading_stiffness: float
    """k of the heading correction [1/s] (0: the policy sees the raw w_z)."""
    stages: list[dict[str, Any]] = field(default_factory=list)
    """Curriculum stages ``{"step": env steps, "lin_vel_x": [..], "ang_vel_z": [..]}``: from ``step`` on, the
    ranges widen to the stage's (empty: the initial ranges throughout)."""
    description: str = ""
    """Meaning of the three command entries."""


@dataclass
class PolicyMetadata:
    """Everything an independent runner needs besides the network (schema ``gmloco-policy``, version 2)."""

    observation: ObservationSpec
    """Observation terms, history and input layout."""
    joints: JointSpec
    """Joints, gains, default pose, action scale and effort limits."""
    timing: TimingSpec
    """Physics and policy periods."""
    contact: ContactSpec
    """Contact model, foot collider, terrain, materials and robot randomization trained on."""
    command: CommandSpec
    """Command ranges trained on."""
    policy_class: str = "MLPModel"
    """Network kind: ``StudentActor`` (outputs actions, latent, eta) or ``MLPModel`` (actions)."""
    latent_dim: int = 0
    """Size of the ``latent`` output (0: none)."""
    commit: str = "unknown"
    """Git commit of the code that trained the policy."""
    run_path: str = "local"
    """Training run identifier (run directory or checkpoint)."""
    schema: str = SCHEMA_NAME
    """Schema name."""
    schema_version: int = SCHEMA_VERSION
    """Schema version."""

    @property
    def obs_dim(self) -> int:
        """Width of one frame o_t."""
        return self.observation.obs_dim

    @property
    def num_actions(self) -> int:
        """Number of actions (actuated joints)."""
        return len(self.joints.names)

    def validate(self) -> None:
        """Check lengths, positive sizes and periods, and dt consistency.

        Raises:
            PolicyMetadataError: Naming the first inconsistent field.
        """
        j, o, t = self.joints, self.observation, self.timing
        lengths = {f.name: len(getattr(j, f.name)) for f in fields(j)}
        bad = {k: n for k, n in lengths.items() if n != len(j.names)}
        if bad:
            raise PolicyMetadataError(f"joints lists must have {len(j.names)} entries (joints.names), got {bad}.")
        for term in o.terms:
            if term.dim < 1 or (isinstance(term.scale, list) and len(term.scale) != term.dim):
                raise PolicyMetadataError(f"observation term {term.name!r}: dim {term.dim}, scale {term.scale}.")
        if o.history_length < 1 or o.history_order != "oldest_first" or not o.terms:
            raise PolicyMetadataError(
                f"observation: history_length {o.history_length} (need >= 1), history_order {o.history_order!r} "
                "(need 'oldest_first'), terms {len(o.terms)} (need >= 1)."
            )
        if t.physics_dt <= 0.0 or t.decimation < 1 or not math.isclose(t.policy_dt, t.physics_dt * t.decimation):
            raise PolicyMetadataError(f"timing {t}: need physics_dt > 0, decimation >= 1, policy_dt = their product.")
        c = self.command
        if c.yaw_command not in YAW_COMMANDS or not c.heading_stiffness >= 0.0:
            raise PolicyMetadataError(
                f"command: yaw_command {c.yaw_command!r} (need one of {list(YAW_COMMANDS)}), heading_stiffness "
                f"{c.heading_stiffness} (need >= 0)."
            )

    def to_dict(self) -> dict[str, Any]:
        """Return the JSON document (nested plain data)."""
        self.validate()
        return asdict(self)

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any]) -> PolicyMetadata:
        """Build from a document written by :meth:`to_dict`.

        Raises:
            PolicyMetadataError: On another schema, an unknown version, missing or unknown fields.
        """
        if doc.get("schema") != SCHEMA_NAME or doc.get("schema_version") != SCHEMA_VERSION:
            raise PolicyMetadataError(
                f"policy metadata is schema {doc.get('schema')!r} version {doc.get('schema_version')!r}; this code "
                f"reads {SCHEMA_NAME!r} version {SCHEMA_VERSION}. Re-export the policy with this version of gmloco."
            )
        try:
            meta = _build(cls, doc)
        except (TypeError, KeyError) as err:
            raise PolicyMetadataError(f"policy metadata document is malformed: {err}") from err
        meta.validate()
        return meta

    def to_props(self) -> dict[str, str]:
        """Return the ONNX ``metadata_props`` entries: ``{METADATA_KEY: JSON document}``."""
        return {METADATA_KEY: json.dumps(self.to_dict())}

    @classmethod
    def from_props(cls, props: Mapping[str, str]) -> PolicyMetadata:
        """Parse the ``metadata_props`` of an exported policy.

        Raises:
            PolicyMetadataError: If the document is missing (a version-1 student file or a foreign export is
                named as such), unreadable JSON, or refused by :meth:`from_dict`.
        """
        if METADATA_KEY not in props:
            if _LEGACY_FORMAT_KEY in props:
                found = f"version-1 student metadata (format {props[_LEGACY_FORMAT_KEY]})"
                why = "which lacks the contact model, foot collider, timing, command ranges and effort limits"
            else:
                found, why = "no gmloco policy metadata", f"no '{METADATA_KEY}' entry among {sorted(props)[:8]}"
            raise PolicyMetadataError(
                f"The policy carries {found} ({why}), so it cannot be run from its metadata. Re-export it with "
                "gmloco (train's export stage), which writes schema "
                f"{SCHEMA_NAME!r} version {SCHEMA_VERSION}."
            )
        try:
            doc = json.loads(props[METADATA_KEY])
        except json.JSONDecodeError as err:
            raise PolicyMetadataError(f"'{METADATA_KEY}' metadata is not valid JSON: {err}") from err
        if not isinstance(doc, dict):
            raise PolicyMetadataError(f"'{METADATA_KEY}' metadata is not a JSON object.")
        return cls.from_dict(doc)


_NESTED: dict[tuple[type, str], type] = {
    (PolicyMetadata, "observation"): ObservationSpec,
    (PolicyMetadata, "joints"): JointSpec,
    (PolicyMetadata, "timing"): TimingSpec,
    (PolicyMetadata, "contact"): ContactSpec,
    (PolicyMetadata, "command"): CommandSpec,
    (ContactSpec, "foot_collider"): FootColliderSpec,
}
"""Dataclass-valued fields, built recursively by :func:`_build`."""


def _build(cls: type, doc: Mapping[str, Any]) -> Any:
    """Build dataclass ``cls`` from ``doc``, nested specs included; unknown keys are an error."""
    names = {f.name for f in fields(cls)}
    unknown = sorted(set(doc) - names)
    if unknown:
        raise KeyError(f"unknown fields {unknown} in {cls.__name__}")
    kwargs: dict[str, Any] = {}
    for key, value in doc.items():
        nested = _NESTED.get((cls, key))
        if nested is not None:
            value = _build(nested, value)
        elif cls is ObservationSpec and key == "terms":
            value = [_build(ObservationTermSpec, t) for t in value]
        kwargs[key] = value
    return cls(**kwargs)


def write_policy_metadata(path: str | Path, metadata: PolicyMetadata) -> None:
    """Add (or replace) the metadata document of the ONNX file at ``path``; the file is replaced atomically."""
    import os

    path = Path(path)
    model = onnx.load(str(path))
    props = metadata.to_props()
    kept = [p for p in model.metadata_props if p.key not in props]
    del model.metadata_props[:]
    model.metadata_props.extend(kept)
    for key, value in props.items():
        model.metadata_props.append(onnx.StringStringEntryProto(key=key, value=value))
    tmp = path.with_name(f".{path.name}.meta.tmp")
    onnx.save(model, str(tmp))
    os.replace(tmp, path)


def read_policy_metadata(path: str | Path) -> PolicyMetadata:
    """Read the metadata of an exported policy (onnx only, no torch, no onnxruntime).

    Raises:
        PolicyMetadataError: If the file holds no readable gmloco policy metadata (see :meth:`PolicyMetadata.from_props`).
    """
    model = onnx.load(str(path), load_external_data=False)
    return PolicyMetadata.from_props({p.key: p.value for p in model.metadata_props})
