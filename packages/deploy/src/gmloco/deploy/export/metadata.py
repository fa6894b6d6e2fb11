# SPDX-License-Identifier: Apache-2.0
"""Deploy metadata of an exported student policy, stored in the ONNX ``metadata_props`` (no torch needed).

Every value is JSON-encoded under its own key, so lists of names and per-joint gains round-trip exactly (mjlab's
exporter writes comma-joined strings instead; the keys that mean the same thing keep mjlab's names).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Literal

import onnx

__all__ = ["METADATA_FORMAT", "PolicyMetadata", "read_policy_metadata", "write_policy_metadata"]

METADATA_FORMAT = "gmloco-student-policy/1"
"""Value of the ``format`` key; bump when a field changes meaning."""


@dataclass
class PolicyMetadata:
    """What the robot side needs to run the policy: joints, gains, observation layout, history, timing."""

    joint_names: list[str]
    """Actuated joints in action order (the order of the policy's action vector)."""
    joint_stiffness: list[float]
    """PD stiffness kp per joint [N m / rad], action order."""
    joint_damping: list[float]
    """PD damping kd per joint [N m s / rad], action order."""
    default_joint_pos: list[float]
    """Nominal pose q_0 per joint [rad]; joint target = q_0 + action_scale * action."""
    action_scale: list[float]
    """Scale from policy action to joint-position offset, per joint [rad]."""
    observation_names: list[str]
    """Terms of one observation frame o_t, in order (e.g. base_ang_vel, projected_gravity, command, ...)."""
    observation_dims: list[int]
    """Size of each term, so term i occupies ``sum(dims[:i]) : sum(dims[:i + 1])`` of o_t."""
    observation_scale: list[float | list[float]]
    """Scale applied to each term after clipping (scalar or per-element), as in the training env."""
    observation_clip: list[list[float] | None]
    """``[low, high]`` clip of each term before scaling, or None for no clip."""
    history_length: int
    """N, frames in the ``history`` input ``[batch, N, obs_dim]``, oldest first, current frame last."""
    policy_dt: float
    """Policy period [s] (0.02 for 50 Hz); the history spans N * policy_dt seconds."""
    history_padding: Literal["repeat_first", "zeros"] = "repeat_first"
    """How the history is filled after a reset: repeat the first frame (mjlab back-fill) or zeros."""
    latent_dim: int = 0
    """Size of the ``latent`` output z_hat (0 if the model has none)."""
    commit: str = "unknown"
    """Git commit of the code that trained the policy."""
    run_path: str = "local"
    """Training run identifier (W&B run path or log directory)."""
    format: str = METADATA_FORMAT
    """Metadata format tag."""

    @property
    def obs_dim(self) -> int:
        """Size of one observation frame o_t."""
        return sum(self.observation_dims)

    @property
    def num_actions(self) -> int:
        """Number of actions (actuated joints)."""
        return len(self.joint_names)

    def validate(self) -> None:
        """Check that per-joint and per-term lists agree in length.

        Raises:
            ValueError: On any length mismatch or a non-positive history length.
        """
        per_joint = {k: len(getattr(self, k)) for k in ("joint_stiffness", "joint_damping", "default_joint_pos")}
        per_joint["action_scale"] = len(self.action_scale)
        bad = {k: n for k, n in per_joint.items() if n != self.num_actions}
        per_term = {k: len(getattr(self, k)) for k in ("observation_dims", "observation_scale", "observation_clip")}
        bad |= {k: n for k, n in per_term.items() if n != len(self.observation_names)}
        if bad:
            raise ValueError(f"Metadata lists of the wrong length: {bad}.")
        if self.history_length < 1 or self.policy_dt <= 0.0:
            raise ValueError("history_length must be >= 1 and policy_dt > 0.")

    def to_props(self) -> dict[str, str]:
        """Return the ONNX ``metadata_props`` entries: field name -> JSON value."""
        self.validate()
        return {key: json.dumps(value) for key, value in asdict(self).items()}

    @classmethod
    def from_props(cls, props: Mapping[str, str]) -> PolicyMetadata:
        """Parse ``metadata_props`` written by :meth:`to_props`; unknown keys are ignored.

        Raises:
            ValueError: If the format tag is missing or unknown, or a required field is absent.
        """
        if "format" not in props or json.loads(props["format"]) != METADATA_FORMAT:
            raise ValueError(f"Not a {METADATA_FORMAT} policy (format={props.get('format')!r}).")
        names = {f.name for f in fields(cls)}
        meta = cls(**{k: json.loads(v) for k, v in props.items() if k in names})
        meta.validate()
        return meta


def write_policy_metadata(path: str | Path, metadata: PolicyMetadata) -> None:
    """Add (or replace) the metadata entries of the ONNX file at ``path``, in place."""
    model = onnx.load(str(path))
    props = metadata.to_props()
    kept = [p for p in model.metadata_props if p.key not in props]
    del model.metadata_props[:]
    model.metadata_props.extend(kept)
    for key, value in props.items():
        model.metadata_props.append(onnx.StringStringEntryProto(key=key, value=value))
    onnx.save(model, str(path))


def read_policy_metadata(path: str | Path) -> PolicyMetadata:
    """Read the metadata of an exported policy (onnx only, no torch, no onnxruntime)."""
    model = onnx.load(str(path), load_external_data=False)
    return PolicyMetadata.from_props({p.key: p.value for p in model.metadata_props})
