# SPDX-License-Identifier: Apache-2.0
"""The run manifest: one record per stage (status, config hash, outputs, timings) plus invocation history."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import Any

from workflows.run_dir import atomic_write_json, list_outputs, read_json

__all__ = ["MANIFEST_VERSION", "Manifest", "StageRecord", "StageStatus"]

MANIFEST_VERSION = 1


class StageStatus(str, Enum):
    """Outcome of one stage in one invocation."""

    DONE = "done"
    """Ran to the end in this invocation; outputs and metrics are recorded."""
    SKIPPED = "skipped"
    """Done earlier for the same config hash and its outputs are intact: not rerun."""
    NOT_IMPLEMENTED = "not_implemented"
    """The stage has no implementation yet (its issue is named in the message)."""
    BLOCKED = "blocked"
    """An upstream stage it needs is not done for the current config."""
    INCOMPLETE = "incomplete"
    """The stage stopped at its time box with resumable state; rerun the same command to continue."""
    DEFERRED = "deferred"
    """Not started because the pipeline's time box was used up."""
    FAILED = "failed"
    """Raised an error; the traceback is in ``<stage>/error.log``."""
    DISABLED = "disabled"
    """Not selected in ``stages``."""

    @property
    def satisfied(self) -> bool:
        """Whether downstream stages may use this stage's outputs."""
        return self in (StageStatus.DONE, StageStatus.SKIPPED)


@dataclass
class StageRecord:
    """What the manifest remembers about one stage."""

    status: StageStatus
    """Latest status."""
    config_hash: str
    """Hash of the stage's config section, the common keys and its upstream hashes."""
    message: str = ""
    """Human-readable reason (issue number, error, time box)."""
    outputs: dict[str, int] = field(default_factory=dict)
    """Files under ``out_dir`` (relative path -> size in bytes) when the stage finished."""
    out_dir: str = ""
    """Output folder of the stage when the record was written (informative; checks use the current one)."""
    metrics: dict[str, Any] = field(default_factory=dict)
    """What ``run(cfg)`` returned."""
    started_at: str = ""
    """ISO-8601 start time of the attempt that produced this record."""
    duration_s: float = 0.0
    """Wall time of that attempt [s]."""
    invocation: int = 0
    """Index into ``Manifest.invocations`` of the attempt that produced this record."""

    def outputs_intact(self, out_dir: str) -> bool:
        """Check that every recorded output exists under ``out_dir`` with its recorded size."""
        current = list_outputs(out_dir)
        return all(current.get(rel) == size for rel, size in self.outputs.items())

    def to_dict(self) -> dict[str, Any]:
        """Return a JSON-ready dict."""
        d = dataclasses.asdict(self)
        d["status"] = self.status.value
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> StageRecord:
        """Build a record from :meth:`to_dict` output, ignoring unknown keys."""
        names = {f.name for f in dataclasses.fields(cls)}
        kwargs = {k: v for k, v in d.items() if k in names}
        kwargs["status"] = StageStatus(kwargs["status"])
        return cls(**kwargs)


@dataclass
class Manifest:
    """``manifest.json`` of a run directory, rewritten atomically after every stage."""

    path: Path
    """Location of ``manifest.json``."""
    stages: dict[str, StageRecord] = field(default_factory=dict)
    """Latest record per stage name."""
    invocations: list[dict[str, Any]] = field(default_factory=list)
    """One entry per command that touched this run (time, argv, git commit, seed, scale)."""
    config_hash: str = ""
    """Hash of the whole resolved config of the latest invocation (volatile keys removed)."""
    exp_name: str = ""
    """Experiment the run directory belongs to ('' until the first invocation records it)."""

    @classmethod
    def load(cls, path: Path) -> Manifest:
        """Read ``path`` or start an empty manifest when it does not exist."""
        raw = read_json(path, default={}) or {}
        stages = {k: StageRecord.from_dict(v) for k, v in raw.get("stages", {}).items()}
        return cls(path, stages, list(raw.get("invocations", [])), raw.get("config_hash", ""), raw.get("exp_name", ""))

    def save(self) -> None:
        """Write the manifest atomically."""
        atomic_write_json(
            self.path,
            {
                "version": MANIFEST_VERSION,
                "exp_name": self.exp_name,
                "config_hash": self.config_hash,
                "stages": {k: v.to_dict() for k, v in self.stages.items()},
                "invocations": self.invocations,
            },
        )

    def is_satisfied(self, stage: str, config_hash: str, out_dir: str) -> bool:
        """Whether ``stage`` finished earlier for ``config_hash`` and its outputs are intact in ``out_dir``.

        ``out_dir`` is the stage's current folder, so a run directory that was moved or copied still resumes.
        """
        rec = self.stages.get(stage)
        return bool(rec and rec.status.satisfied and rec.config_hash == config_hash and rec.outputs_intact(out_dir))
