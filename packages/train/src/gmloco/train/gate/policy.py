# SPDX-License-Identifier: Apache-2.0
"""What the gate reads from a run folder: the acting policy's kind, its training task and its GPU minutes."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from gmloco.train.config import GranularTaskCfg

__all__ = ["GateInputError", "GatePolicy", "gpu_minutes", "read_policy"]

PolicyKind = Literal["student", "teacher", "ppo"]
"""Acting policy: a ``StudentPPO`` or ``TeacherPPO`` checkpoint, or an mjlab ONNX export of vanilla PPO."""

_BEFORE_FIELDS: dict[str, Any] = {
    "foot_faces": "sole",
    "yaw_command": "heading_envs",
    "heading_stiffness": 0.5,
    "rft_extensions_file": "results/sand_calibration/rft3d_calibrated.json",
    "rft_extension_ranges": {},
}
"""Task fields absent from runs trained before they existed, and the behaviour those runs had (the sole-only RFT
collider; mjlab's heading envs, whose heading control uses stiffness 0.5; no fitted RFT terms, none randomized)."""


class GateInputError(ValueError):
    """A run folder the gate cannot evaluate; the message says what is missing and what to pass."""


@dataclass
class GatePolicy:
    """A run folder resolved: kind, policy file, training config."""

    kind: PolicyKind
    """Acting policy kind."""
    path: Path
    """``checkpoint.pt`` (student, teacher) or ``policy.onnx`` (PPO)."""
    task: GranularTaskCfg
    """The task the policy was trained on (fields absent from old runs: ``_BEFORE_FIELDS``)."""
    train_cfg: dict[str, Any]
    """The run's ``TrainRunCfg`` as JSON (``rsl_rl_overrides``, ``history_length``, ``hidden_dims``)."""


def _train_cfg(folder: Path) -> dict[str, Any]:
    """``train_cfg.json``, else the ``train_cfg`` of ``summary.json`` (a chunk's output folder)."""
    if (folder / "train_cfg.json").is_file():
        return json.loads((folder / "train_cfg.json").read_text())
    if (folder / "summary.json").is_file():
        cfg = json.loads((folder / "summary.json").read_text()).get("train_cfg")
        if isinstance(cfg, dict) and "task" in cfg:
            return cfg
    raise GateInputError(
        f"{folder} holds neither train_cfg.json nor a summary.json with train_cfg: the gate rebuilds the training "
        "task from it. Pass a run folder under artifacts/ (e.g. artifacts/gm_loco_student_td)."
    )


def _kind(train_cfg: dict[str, Any]) -> PolicyKind:
    """Student or teacher from the actor class of the run's rsl-rl entries; vanilla PPO when there are none."""
    actor = str(train_cfg.get("rsl_rl_overrides", {}).get("actor", {}).get("class_name", ""))
    if actor.endswith(":StudentActor"):
        return "student"
    if actor.endswith(":TeacherActor"):
        return "teacher"
    return "ppo"


def read_policy(folder: str | Path) -> GatePolicy:
    """Resolve a run folder into the policy the gate evaluates.

    Raises:
        GateInputError: If the folder, its config or its policy file is missing.
    """
    from gmloco.train.tasks.g1_granular.upgrade_metadata import task_from_dict

    root = Path(folder)
    if not root.is_dir():
        raise GateInputError(f"--policy {root}: no such folder; pass a run folder such as artifacts/gm_loco_student_td")
    train_cfg = _train_cfg(root)
    kind = _kind(train_cfg)
    path = root / ("policy.onnx" if kind == "ppo" else "checkpoint.pt")
    if not path.is_file():
        raise GateInputError(f"{root} is a {kind} run but has no {path.name}; the gate evaluates {path.name} there.")
    overrides = {k: v for k, v in _BEFORE_FIELDS.items() if k not in train_cfg["task"]}
    return GatePolicy(kind, path, task_from_dict(train_cfg["task"], overrides), train_cfg)


def _run_minutes(folder: Path) -> float | None:
    """GPU minutes of one run folder: ``manifest.json`` ``gpu_minutes_total``, else a GPU chunk's summary wall time."""
    if (folder / "manifest.json").is_file():
        value = json.loads((folder / "manifest.json").read_text()).get("gpu_minutes_total")
        if value is not None:
            return float(value)
    if (folder / "summary.json").is_file():
        summary = json.loads((folder / "summary.json").read_text())
        wall = summary.get("metrics", {}).get("wall_seconds")
        if wall is not None and str(summary.get("device", "cpu")) != "cpu":
            return float(wall) / 60.0
    return None


def gpu_minutes(folder: str | Path) -> dict[str, float | None]:
    """GPU minutes of the run and, for a student, of the teacher its checkpoint names (``teacher_source``).

    Returns:
        ``run``, ``teacher`` (None if not a student or not recorded) and ``total`` [min] (None if the run's are
        not recorded).
    """
    import torch

    root = Path(folder)
    run = _run_minutes(root)
    teacher = None
    ckpt = root / "checkpoint.pt"
    if ckpt.is_file():
        source = torch.load(ckpt, map_location="cpu", weights_only=False, mmap=True).get("teacher_source")
        if source:
            teacher = _run_minutes(Path(source).parent)
    total = None if run is None else run + (teacher or 0.0)
    return {"run": run, "teacher": teacher, "total": total}
