# SPDX-License-Identifier: Apache-2.0
"""Run metadata: the ``gmloco.run`` MCAP metadata record (string keys and values)."""

from __future__ import annotations

import json
import subprocess
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Literal

from gmloco.deploy.g1 import G1_JOINT_NAMES
from gmloco.deploy.logs.errors import LogFormatError
from gmloco.deploy.logs.schema import SCHEMA_VERSION, UNITS

__all__ = ["RunMetadata", "git_commit"]

_JSON_KEYS = ("joint_names", "units", "extra")


@dataclass
class RunMetadata:
    """Who, what and where of one recording; written once, before the first message."""

    controller: str
    """Controller label: ``"policy"`` for a trained policy, ``"scripted_stepping"`` for the scripted gait, ..."""
    policy: str = "none"
    """Policy identity (run id, ONNX file name and hash), ``"none"`` when no policy ran."""
    material: str = "rigid"
    """Ground material, e.g. ``"rigid"``, ``"sand_loose"``, ``"sand_packed"``, or a transition ``"rigid->sand_loose"``."""
    contact_model: str = "rigid"
    """Simulator contact model (``"rigid"``, ``"rft3d"``, ...); ``"hardware"`` for real runs."""
    source: Literal["sim", "real"] = "sim"
    """Where the data come from."""
    commit: str = "unknown"
    """Git commit of the code that produced the run."""
    commit_dirty: bool = False
    """Whether the working tree had uncommitted changes."""
    robot: str = "unitree_g1_29dof"
    """Robot variant; only the 29-DoF G1 is supported."""
    joint_names: tuple[str, ...] = G1_JOINT_NAMES
    """Order of every per-joint JSON array in the file (``/lowcmd``, ``/lowstate/motor_aux``)."""
    lowstate_rate_hz: float = 500.0
    """Nominal rate of ``/lowstate/*`` and ``/lowcmd`` [Hz]."""
    control_rate_hz: float = 50.0
    """Nominal rate of the controller (command, policy and eta topics) [Hz]."""
    support: str = "none"
    """External support of the robot: ``"none"``, ``"gantry"`` or ``"fixed"`` (pelvis held still; the mismatch replay
    welds it), or the simulator's virtual harness with its gains."""
    created_utc: str = ""
    """ISO-8601 UTC creation time; empty for reproducible sample files."""
    notes: str = ""
    """Free text (operator notes, scenario description)."""
    units: dict[str, str] = field(default_factory=lambda: dict(UNITS))
    """Unit of every signal as written; the reader refuses a file whose units differ from the schema."""
    schema_version: str = SCHEMA_VERSION
    """Schema version the file was written with."""
    extra: dict[str, str] = field(default_factory=dict)
    """Further key/value pairs (controller parameters, scenario settings)."""

    def to_record(self) -> dict[str, str]:
        """Return the string-to-string mapping stored in the MCAP metadata record."""
        out: dict[str, str] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in _JSON_KEYS:
                out[f.name] = json.dumps(list(value) if isinstance(value, tuple) else value)
            elif isinstance(value, bool):
                out[f.name] = "true" if value else "false"
            else:
                out[f.name] = str(value)
        return out

    @classmethod
    def from_record(cls, record: dict[str, str]) -> RunMetadata:
        """Parse a metadata record; unknown keys go to :attr:`extra`.

        Raises:
            LogFormatError: If a key is malformed or ``controller`` is missing.
        """
        if "controller" not in record:
            raise LogFormatError("run metadata has no 'controller' key; every run must say what controlled the robot")
        known = {f.name: f for f in fields(cls)}
        kwargs: dict = {}
        extra = {}
        for key, value in record.items():
            if key not in known:
                extra[key] = value
            elif key in _JSON_KEYS:
                try:
                    kwargs[key] = json.loads(value)
                except json.JSONDecodeError as exc:
                    raise LogFormatError(f"run metadata key {key!r} is not valid JSON: {exc}") from None
            elif key == "commit_dirty":
                kwargs[key] = value.lower() == "true"
            elif key in ("lowstate_rate_hz", "control_rate_hz"):
                kwargs[key] = float(value)
            else:
                kwargs[key] = value
        kwargs["joint_names"] = tuple(kwargs.get("joint_names", G1_JOINT_NAMES))
        kwargs["extra"] = {**kwargs.get("extra", {}), **extra}
        return cls(**kwargs)


def git_commit(path: str | Path = ".") -> tuple[str, bool]:
    """Return ``(commit, dirty)`` of the git work tree at ``path``, ``("unknown", False)`` outside git."""
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=path, capture_output=True, text=True, check=True
        ).stdout.strip()
        status = subprocess.run(
            ["git", "status", "--porcelain"], cwd=path, capture_output=True, text=True, check=True
        ).stdout
    except (OSError, subprocess.CalledProcessError):
        return "unknown", False
    return commit, bool(status.strip())
