# SPDX-License-Identifier: Apache-2.0
"""Structured-config schemas of the pipeline, registered in Hydra's ConfigStore.

Each ``conf/<group>/*.yaml`` extends its schema through its defaults list (``- base_<group>``), so a typo in
an override or a YAML file fails at composition with the key's name. The stage sections are placeholders that
the packages replace with their own ``FooCfg`` dataclasses as the stages get implemented (issues 4, 6-9).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import Any

from hydra.core.config_store import ConfigStore
from omegaconf import MISSING, OmegaConf

from stage_registry import stage_names

__all__ = [
    "AnalyzeLogsCfg",
    "ContactModelName",
    "DistillCfg",
    "EvalMpmCfg",
    "ExportCfg",
    "MismatchCfg",
    "PathsCfg",
    "PipelineCfg",
    "ScaleName",
    "StageCfg",
    "SweepCfg",
    "TrackingCfg",
    "TrainTeacherCfg",
    "WandbMode",
    "register_configs",
]

REPO_ROOT = Path(__file__).resolve().parents[1]
"""Checkout root (``workflows/..``); used only as the default of ``paths.root_dir``."""


def _interp(expr: str) -> Any:
    """Return an OmegaConf interpolation as a typed field default (resolved at access time)."""
    return expr


class ContactModelName(str, Enum):
    """Granular contact models of ``gmloco.contact`` (issue 3)."""

    rft3d = "rft3d"
    heuristic_rft = "heuristic_rft"
    cone_single = "cone_single"
    cone_multi = "cone_multi"
    rigid = "rigid"


class ScaleName(str, Enum):
    """Run scale: ``full`` on a GPU, ``smoke`` (tiny, minutes on a CPU) otherwise."""

    full = "full"
    smoke = "smoke"


class WandbMode(str, Enum):
    """Value given to ``WANDB_MODE``."""

    offline = "offline"
    online = "online"
    disabled = "disabled"


@dataclass
class PathsCfg:
    """Where things live; every path is absolute after resolution."""

    root_dir: str = _interp("${oc.env:GMLOCO_ROOT,${gmloco.repo_root:}}")
    """Checkout root (env ``GMLOCO_ROOT`` overrides)."""
    runs_dir: str = _interp("${paths.root_dir}/runs")
    """Parent of all run directories: ``<runs_dir>/<exp_name>/<run_name>``."""
    data_dir: str = _interp("${paths.root_dir}/data")
    """Inputs that are not code (recordings, material tables)."""
    hw_logs_dir: str = _interp("${paths.data_dir}/logs")
    """MCAP robot recordings read by ``analyze_logs`` and ``mismatch``."""


@dataclass
class TrackingCfg:
    """Experiment tracking: TensorBoard always, wandb offline unless turned on."""

    tensorboard: bool = True
    """Write pipeline-level scalars (stage metrics, durations) to ``<run_dir>/tb``."""
    wandb: WandbMode = WandbMode.offline
    """Exported as ``WANDB_MODE``; ``online`` syncs, ``offline`` keeps files in ``<run_dir>/wandb``."""
    wandb_project: str = "gmloco"
    """wandb project name."""


@dataclass
class StageCfg:
    """Fields every stage has."""

    out_dir: str = MISSING
    """Folder the stage writes its outputs to (``metrics.json`` is added by the runner)."""
    max_minutes: float | None = _interp("${max_minutes}")
    """Time box of the stage [min]; it saves resumable state and stops when reached. None: no limit."""


@dataclass
class TrainTeacherCfg(StageCfg):
    """PPO teacher on mjlab with a granular contact model (issues 4, 6)."""

    out_dir: str = _interp("${run_dir}/train_teacher")
    contact_model: ContactModelName = ContactModelName.rft3d
    """Granular contact model applied to the feet."""
    num_envs: int = 4096
    """Parallel environments (rsl_rl / mjlab name)."""
    max_iterations: int = 5000
    """PPO iterations."""


@dataclass
class DistillCfg(StageCfg):
    """TCN student distilled from the teacher with DAgger + PPO (issue 6)."""

    out_dir: str = _interp("${run_dir}/distill")
    teacher_dir: str = _interp("${train_teacher.out_dir}")
    """Folder holding the teacher checkpoint."""
    num_envs: int = 4096
    """Parallel environments."""
    max_iterations: int = 2000
    """Distillation iterations."""


@dataclass
class ExportCfg(StageCfg):
    """ONNX export of the student with deploy metadata (issue 6)."""

    out_dir: str = _interp("${run_dir}/export")
    policy_dir: str = _interp("${distill.out_dir}")
    """Folder holding the student checkpoint."""


@dataclass
class EvalMpmCfg(StageCfg):
    """Evaluation on Newton implicit-MPM sand (issue 9)."""

    out_dir: str = _interp("${run_dir}/eval_mpm")
    policy_dir: str = _interp("${export.out_dir}")
    """Folder holding ``policy.onnx``."""
    num_episodes: int = 100
    """Episodes per (policy, terrain, scenario); the paper uses 100."""
    episode_s: float = 10.0
    """Episode length [s]."""
    voxel_size: float = 0.03
    """MPM voxel size [m]."""


@dataclass
class AnalyzeLogsCfg(StageCfg):
    """MCAP robot-log analysis (issue 7)."""

    out_dir: str = _interp("${run_dir}/analyze_logs")
    logs_dir: str = _interp("${paths.hw_logs_dir}")
    """Folder of ``*.mcap`` recordings."""


@dataclass
class MismatchCfg(StageCfg):
    """Sim-vs-real mismatch discovery (issue 8)."""

    out_dir: str = _interp("${run_dir}/mismatch")
    logs_dir: str = _interp("${paths.hw_logs_dir}")
    """Folder of real ``*.mcap`` recordings."""


@dataclass
class SweepCfg:
    """Optuna search over pipeline overrides (the sweep workflow is not implemented yet)."""

    metric: str = MISSING
    """``<stage>/<metric>`` returned by a stage's ``run(cfg)``."""
    direction: str = "maximize"
    """``maximize`` or ``minimize``."""
    n_trials: int = 20
    """Trials in the study."""
    sampler_seed: int = _interp("${seed}")
    """Seed of the TPE sampler (seeded samplers make sweeps reproducible)."""
    storage: str = _interp("sqlite:///${paths.runs_dir}/optuna.db")
    """Optuna storage URL (an RDB URL shares one study across machines)."""
    params: dict[str, Any] = field(default_factory=dict)
    """Search space: override key -> ``{type: float|int|categorical, low, high, log, choices}``."""


@dataclass
class PipelineCfg:
    """Top-level config of ``full_pipeline.py`` and of every stage workflow."""

    exp_name: str = MISSING
    """Experiment name, set by ``+exp=<name>``; also the run directory's parent folder."""
    run_name: str = _interp("${now:%Y%m%d-%H%M%S}")
    """Run directory name; reuse it (or ``run_dir``) to resume."""
    run_dir: str = _interp("${paths.runs_dir}/${exp_name}/${run_name}")
    """The run directory (config, git state, manifest, stage outputs)."""
    seed: int = 42
    """Seed given to ``seed_everything`` before any stage."""
    device: str = "auto"
    """``auto`` (cuda when available), ``cpu``, ``cuda`` or ``cuda:N``."""
    scale: ScaleName = ScaleName.full
    """Set by the ``scale`` group; ``smoke`` is applied automatically on a CPU-only machine."""
    max_minutes: float | None = None
    """Time box of the whole invocation [min]; stages after it are deferred. None: no limit."""
    force: Any = False
    """Rerun stages even when done for the same config: ``true`` (all) or a list, e.g. ``[export]``."""
    stages: list[str] = field(default_factory=stage_names)
    """Stages to run, in pipeline order."""
    paths: PathsCfg = field(default_factory=PathsCfg)
    tracking: TrackingCfg = field(default_factory=TrackingCfg)
    train_teacher: TrainTeacherCfg = field(default_factory=TrainTeacherCfg)
    distill: DistillCfg = field(default_factory=DistillCfg)
    export: ExportCfg = field(default_factory=ExportCfg)
    eval_mpm: EvalMpmCfg = field(default_factory=EvalMpmCfg)
    analyze_logs: AnalyzeLogsCfg = field(default_factory=AnalyzeLogsCfg)
    mismatch: MismatchCfg = field(default_factory=MismatchCfg)
    sweep: SweepCfg | None = None
    """Optuna sweep settings, set by ``+sweep=<name>``; None outside sweeps."""


def register_configs() -> None:
    """Register the schemas and the ``gmloco.repo_root`` resolver (idempotent)."""
    if not OmegaConf.has_resolver("gmloco.repo_root"):
        OmegaConf.register_new_resolver("gmloco.repo_root", lambda: str(REPO_ROOT))
    cs = ConfigStore.instance()
    cs.store(name="base_pipeline", node=PipelineCfg)
    cs.store(group="paths", name="base_paths", node=PathsCfg)
    cs.store(group="tracking", name="base_tracking", node=TrackingCfg)
    cs.store(group="sweep", name="base_sweep", node=SweepCfg, package="sweep")


register_configs()
