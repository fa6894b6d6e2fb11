# SPDX-License-Identifier: Apache-2.0
"""The pipeline's stages, in order, with the issue that implements each one.

To implement a stage (today only ``eval_mpm`` is missing), replace ``run = not_implemented("<stage>")`` in
``workflows/<stage>.py`` with a real
``def run(cfg: DictConfig) -> dict[str, float]`` that writes its files under ``cfg.<stage>.out_dir`` and
returns its metrics. Nothing here needs to change unless the stage's inputs (``needs``) change.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

__all__ = [
    "STAGES",
    "StageFn",
    "StageIncompleteError",
    "StageNotImplementedError",
    "StageSpec",
    "issue_text",
    "load_stage_fn",
    "not_implemented",
    "stage_names",
]

StageFn = Callable[[Any], Mapping[str, Any]]
"""A stage entry: ``run(cfg) -> metrics``."""


@dataclass(frozen=True)
class StageSpec:
    """One pipeline stage."""

    name: str
    """Stage name; also its config section (``cfg.<name>``), output folder and workflow module."""
    issues: tuple[int, ...]
    """Issues that implement it (reported while it is not implemented)."""
    needs: tuple[str, ...] = ()
    """Upstream stages whose outputs it reads; it is blocked until they are done for the current config."""
    summary: str = ""
    """One line for the summary table."""
    module: str = ""
    """Module that defines ``run(cfg)``; defaults to ``workflows.<name>`` (i.e. ``workflows/<name>.py``)."""
    fn: StageFn | None = None
    """Direct callable (tests register toy stages this way); overrides ``module``."""


STAGES: tuple[StageSpec, ...] = (
    StageSpec("train_teacher", (4, 6), (), "PPO (ppo_*) or VAE teacher (gm_loco) on mjlab + granular contact"),
    StageSpec("distill", (6,), ("train_teacher",), "TCN student, DAgger + PPO distillation"),
    StageSpec("export", (6,), ("distill",), "ONNX student with deploy metadata + CPU runner check"),
    StageSpec("eval_mpm", (9,), ("export",), "G1 on Newton implicit-MPM sand, paper metrics"),
    StageSpec("analyze_logs", (7,), (), "MCAP robot-log analysis and hardware figures"),
    StageSpec("mismatch", (8,), (), "sim-vs-real mismatch discovery report"),
)
"""Default registry, in execution order."""


def stage_names(registry: tuple[StageSpec, ...] = STAGES) -> list[str]:
    """Return the stage names of ``registry`` in order."""
    return [s.name for s in registry]


def issue_text(issues: tuple[int, ...]) -> str:
    """Format issue numbers as ``issue 6`` or ``issues 4, 6``."""
    nums = ", ".join(str(i) for i in issues)
    return f"issue {nums}" if len(issues) == 1 else f"issues {nums}"


class StageNotImplementedError(NotImplementedError):
    """Raised by a stage that has no implementation yet."""

    def __init__(self, stage: str, issues: tuple[int, ...]) -> None:
        """Build the message ``<stage>: not implemented yet (issue N)``."""
        self.stage = stage
        self.issues = issues
        super().__init__(f"not implemented yet ({issue_text(issues)})")


class StageIncompleteError(RuntimeError):
    """Raised by a stage that stopped at its time box after saving resumable state."""


def not_implemented(name: str) -> StageFn:
    """Return a ``run(cfg)`` that raises :class:`StageNotImplementedError` for stage ``name``."""
    spec = next(s for s in STAGES if s.name == name)

    def run(cfg: Any) -> Mapping[str, Any]:
        """Refuse to run: this stage is not implemented yet."""
        raise StageNotImplementedError(spec.name, spec.issues)

    run.gmloco_not_implemented = spec.issues  # type: ignore[attr-defined]
    return run


def load_stage_fn(spec: StageSpec) -> StageFn:
    """Import the stage's module lazily (heavy dependencies load only when the stage runs) and return ``run``."""
    if spec.fn is not None:
        return spec.fn
    module = importlib.import_module(spec.module or f"workflows.{spec.name}")
    return module.run
