# SPDX-License-Identifier: Apache-2.0
"""Structured-config schemas of the pipeline, registered in Hydra's ConfigStore.

Each ``conf/<group>/*.yaml`` extends its schema through its defaults list (``- base_<group>``), so a typo in
an override or a YAML file fails at composition with the key's name. Where a package dataclass is the config it is
used as it is: the PPO settings (``gmloco.train.teacher_student.PpoCfg``), the teacher's networks and losses
(``teacher_student.TeacherCfg``), the distillation and the student (``teacher_student.DistillCfg``,
``StudentCfg``), the training material (``gmloco.train.MaterialRangeCfg``), the MPM evaluation
(``gmloco.eval.g1.config.G1EvalCfg``) and the sweep's and ablation's evaluation cells
(``gmloco.train.evaluation_cells.MaterialCellsCfg``) are extended with the stage's fields and defaults, not copied;
a stage turns its section back into the package dataclass with ``workflows.section_cfg.section_as``. The train
stage builds ``GranularTaskCfg`` (whose ``Literal`` fields OmegaConf cannot hold) from the section's names, then
sets the fields ``train_teacher.task`` names by their paths (``workflows/task_fields.py``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import Any

from hydra.core.config_store import ConfigStore
from omegaconf import MISSING, DictConfig, OmegaConf

from gmloco.eval.g1.config import G1EvalCfg, Scenario
from gmloco.train.config import MaterialRangeCfg
from gmloco.train.evaluation_cells import MaterialCellsCfg
from gmloco.train.tasks.g1_jump.config import JumpImitationCfg
from gmloco.train.teacher_student.config import DistillCfg as DistillAlgorithmCfg
from gmloco.train.teacher_student.config import PpoCfg, StudentCfg, TeacherCfg
from workflows.config_ranges import each, ranged
from workflows.stage_registry import stage_names

__all__ = [
    "AblationCfg",
    "AblationSource",
    "AnalyzeLogsCfg",
    "ContactModelName",
    "DistillCfg",
    "EvalMpmCfg",
    "ExportCfg",
    "GranularEvalCfg",
    "JumpMotion",
    "JumpSectionCfg",
    "MismatchCfg",
    "PathsCfg",
    "PipelineCfg",
    "PolicyTrainingCfg",
    "ScaleName",
    "StageCfg",
    "SweepCfg",
    "SweepEvalCfg",
    "TerrainName",
    "TrackingCfg",
    "TrainAlgorithm",
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
    """Granular contact models of ``gmloco.contact`` (issue 3): ``gmloco.train.config.ContactModelName``'s names.

    OmegaConf holds no ``Literal``, so the schema's closed choices are enums whose names are the package's
    (``tests/workflows/test_schemas.py`` checks that they agree).
    """

    rft3d = "rft3d"
    heuristic_rft = "heuristic_rft"
    cone_multi = "cone_multi"
    cone_single = "cone_single"
    rigid = "rigid"
    rft3d_calibrated = "rft3d_calibrated"


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
    """Your own MCAP robot recordings (add them to ``analyze_logs.inputs`` or set ``mismatch.real``)."""
    sample_logs_dir: str = _interp("${paths.root_dir}/packages/deploy/data/sample_logs")
    """Committed sample recordings (scripted controller in the project's simulator), the default inputs."""


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
    max_minutes: float | None = ranged(_interp("${max_minutes}"), gt=0)
    """Time box of the stage [min]; it saves resumable state and stops when reached. None: no limit."""
    resume: bool = True
    """Continue from resumable state in ``out_dir``. Set by the runner: false when the stage is forced or its
    config changed since its last record, so it starts fresh."""


class TrainAlgorithm(str, Enum):
    """What the train stage trains."""

    ppo = "ppo"
    """Vanilla PPO (``+exp=ppo_*``, the paper's contact-model ablation): ``gmloco.train.train``."""
    vae_teacher = "vae_teacher"
    """GM-Loco teacher: PPO with the VAE terrain encoder and eta decoder (``TeacherPPO``, ``+exp=gm_loco``)."""


class FootClearanceForm(str, Enum):
    """Form of the swing-height term: ``gmloco.train.config.FootClearanceName``'s names."""

    penalty = "penalty"
    reward = "reward"
    touchdown = "touchdown"
    """The penalty plus the swing's lift out of its footprint, paid at touchdown (12 cm cap)."""
    sinkage = "sinkage"
    """The touchdown terms with a target of 9 cm above the surface plus the footprint's depth (at most 20 cm)."""


class TerrainName(str, Enum):
    """Sand beds of ``gmloco.train.g1_granular_task``: ``gmloco.train.config.TerrainName``'s names."""

    flat = "flat"
    rough = "rough"
    deep = "deep"


class JumpMotion(str, Enum):
    """Jump references of ``gmloco.train.tasks.g1_jump`` (``data/jump_<name>.npz``): ``JumpMotionName``'s names."""

    vertical = "vertical"
    forward = "forward"


@dataclass
class JumpSectionCfg(JumpImitationCfg):
    """The jump imitation task of the train stage: the package's ``JumpImitationCfg`` (issue 39).

    ``train_teacher.jump.rewards.*`` and ``train_teacher.jump.assist.*`` are the package's ``JumpRewardCfg`` and
    ``JumpAssistCfg``; an assist ``initial_scale`` of 0 (or ``enabled: false``) trains without the wrench.
    """

    motion: JumpMotion = JumpMotion.vertical  # type: ignore[assignment]  # OmegaConf holds an Enum, not a Literal
    """Reference motion: 8 cm vertical jump or 10 cm forward jump (``JumpMotionName``'s names)."""


@dataclass
class PolicyTrainingCfg(StageCfg):
    """Fields shared by the two training stages (``gmloco.train.TrainRunCfg``)."""

    num_envs: int = ranged(4096, ge=1)
    """Parallel environments (rsl_rl / mjlab name)."""
    max_iterations: int = ranged(5000, ge=1)
    """Iterations in total over all resumed calls."""
    num_steps_per_env: int = ranged(24, ge=1)
    """Env steps per env and iteration."""
    save_interval: int = ranged(50, ge=1)
    """Iterations between checkpoints (one is always written when a call ends)."""
    ppo: PpoCfg = field(default_factory=PpoCfg)
    """PPO hyper-parameters (``gmloco.train.teacher_student.PpoCfg``; GM-Loco values by default)."""
    gpus: list[int] = field(default_factory=list, metadata=each(integer=True, ge=0))
    """CUDA devices to train on, e.g. ``[0,1]``: several train data-parallel, one rank per GPU with the full
    ``num_envs`` each (``gmloco.train.TrainRunCfg.gpus``). Empty: the pipeline's ``device``."""


@dataclass
class TrainTeacherCfg(TeacherCfg, PolicyTrainingCfg):
    """Train stage: vanilla PPO or the GM-Loco VAE teacher on mjlab with a granular contact model (issues 4, 6).

    The stage's training fields plus the package's ``gmloco.train.teacher_student.TeacherCfg`` (networks, VAE
    encoder and decoder, loss weights, the PPO settings), all at ``train_teacher.<field>``.
    """

    out_dir: str = _interp("${run_dir}/train_teacher")
    algorithm: TrainAlgorithm = TrainAlgorithm.vae_teacher
    """Vanilla PPO (``+exp=ppo_*``) or the VAE teacher (``+exp=gm_loco``)."""
    contact_model: ContactModelName = ContactModelName.rft3d
    """Granular contact model applied to the feet; ``contact=<model>`` (``conf/contact/``) sets it."""
    terrain: TerrainName = TerrainName.flat
    """Sand bed: flat soft sand, sinusoidal rough surface, or a 30 cm deep loose bed."""
    policy_history_length: int = ranged(5, ge=1)
    """Actor frames stacked into o_t (1 for the teacher-student: the history goes through the encoders)."""
    curriculum_scale: float = ranged(1.0, gt=0)
    """Multiplier on the command-stage steps and tracking-ramp length (1.0: GM-Loco's, stages at 10k and 15k
    iterations; 0.1 fits a ~2k-iteration budget). See ``gmloco.train.GranularTaskCfg.curriculum_scale``."""
    foot_clearance: FootClearanceForm = FootClearanceForm.penalty
    """Swing-height term: the project page's L2 penalty or the public code's exp reward (pays standing still)."""
    hidden_dims: list[int] = field(default_factory=lambda: [512, 256, 128], metadata=each(integer=True, ge=1))
    """Actor and critic MLP widths (``gmloco.train.TrainRunCfg.hidden_dims``; GM-Loco: 512, 256, 128); the VAE
    teacher's ``actor_hidden_dims`` and ``critic_hidden_dims`` follow it unless set."""
    actor_hidden_dims: tuple[int, ...] = field(default=_interp("${.hidden_dims}"), metadata=each(integer=True, ge=1))
    """VAE teacher's actor MLP widths (``TeacherCfg.actor_hidden_dims``); default: ``hidden_dims``."""
    critic_hidden_dims: tuple[int, ...] = field(default=_interp("${.hidden_dims}"), metadata=each(integer=True, ge=1))
    """VAE teacher's critic MLP widths (``TeacherCfg.critic_hidden_dims``); default: ``hidden_dims``."""
    warm_start_ppo: str | None = None
    """vae_teacher: a vanilla-PPO checkpoint of the same task (e.g. ``artifacts/ppo_rft3d/checkpoint.pt``) whose
    actor and critic start a fresh teacher run; null: from scratch."""
    history_length: int = ranged(50, ge=1)
    """N, frames of the ``history`` group the teacher encoder reads (the student reads the same N)."""
    jump: JumpSectionCfg | None = None
    """Train the jump imitation task (``task=jump``, as ``+exp=jump_rft3d|jump_rigid`` pick it; needs ``algorithm:
    ppo``) instead of the velocity task; ``terrain`` and ``foot_clearance`` are then unused. null: the velocity task."""
    material: MaterialRangeCfg = field(default_factory=MaterialRangeCfg)
    """Per-env granular material of the velocity task (``gmloco.train.MaterialRangeCfg``): the ranges of mu_int,
    packing, bulk_density, ... drawn on every reset, or one ``preset`` (``train_teacher.material.mu_int=[0.3,0.6]``,
    ``train_teacher.material.preset=dry_sand``, or ``material=dry_sand`` from ``conf/material/``). A field left at
    its default keeps the terrain's value (the deep bed's mu_int 0.1-0.4); the VAE teacher's held-out rectangle is
    then cut out of the ranges."""
    task: dict[str, Any] = field(default_factory=dict)
    """Fields of the velocity task (``gmloco.train.GranularTaskCfg``: domain randomization, curricula, rewards, the
    sand bed) set over the task the section builds, by their path: ``+train_teacher.task.robot_dr.push_velocity=1``,
    ``+train_teacher.task.material.mu_int.0=0.2`` (a digit part sets one end of a range). Checked before any stage
    runs; the distill stage trains on the same task. Empty: the task as built (``workflows/task_fields.py``)."""


@dataclass
class DistillCfg(StudentCfg, DistillAlgorithmCfg, PolicyTrainingCfg):
    """TCN student distilled from the teacher with DAgger + PPO (issue 6).

    The stage's training fields plus the package's ``gmloco.train.teacher_student.DistillCfg`` (loss weights, their
    curriculum, the teacher checkpoint and the PPO settings) and ``teacher_student.StudentCfg`` (the TCN history
    encoder and the actor), all at ``distill.<field>``.
    """

    out_dir: str = _interp("${run_dir}/distill")
    teacher_dir: str = _interp("${train_teacher.out_dir}")
    """Folder holding the teacher checkpoint (newest ``model_<it>.pt``), unless ``teacher_checkpoint`` names one."""
    max_iterations: int = ranged(2000, ge=1)
    actor_hidden_dims: tuple[int, ...] = field(
        default=_interp("${train_teacher.actor_hidden_dims}"), metadata=each(integer=True, ge=1)
    )
    """Student actor MLP widths (``StudentCfg.actor_hidden_dims``); the teacher's, so the student starts from its
    actor."""
    history_length: int = ranged(_interp("${train_teacher.history_length}"), integer=True, ge=1)
    """N, history frames the TCN reads (``StudentCfg.history_length``); the teacher encoder's N."""


@dataclass
class ExportCfg(StageCfg):
    """ONNX export of the student with deploy metadata and an onnxruntime check (issue 6)."""

    out_dir: str = _interp("${run_dir}/export")
    policy_dir: str = _interp("${distill.out_dir}")
    """Folder holding the student checkpoint (newest ``model_<it>.pt``)."""
    parity_atol: float = ranged(1.0e-5, gt=0)
    """Largest onnxruntime-vs-torch difference accepted, on random and on rollout inputs."""
    check_steps: int = ranged(25, ge=1)
    """Env steps rolled out with the ONNX runner, compared with the torch student and the teacher."""


@dataclass(frozen=True)
class EvalMpmCfg(G1EvalCfg):
    """Evaluation on Newton implicit-MPM sand (issue 9): ``gmloco.eval.g1.config.G1EvalCfg`` with the stage's defaults.

    Every ``G1EvalCfg`` field sits at ``eval_mpm.<field>``, its nested numerics and window too
    (``eval_mpm.solver.voxel_size``, ``eval_mpm.window.length``). The numerics and window defaults are the setting
    the convergence check accepted (``docs/mpm_eval.md``); ``seed`` and ``device`` follow the pipeline's.
    """

    out_dir: str = _interp("${run_dir}/eval_mpm")
    max_minutes: float | None = ranged(_interp("${max_minutes}"), gt=0)
    """Time box of the stage [min]; it saves resumable state and stops when reached. None: no limit."""
    policy_dir: str = _interp("${export.out_dir}")
    """Folder holding ``policy.onnx``."""
    policy_file: str = "policy.onnx"
    """File in ``policy_dir`` (gmloco student export or mjlab actor export)."""
    policy_path: str = _interp("${.policy_dir}/${.policy_file}")
    policy_name: str = _interp("${exp_name}")
    """The policy's name in the tables and figures (the experiment that trained it, by default)."""
    terrains: tuple[str, ...] = ("basalt", "dry_sand", "poppy_seed", "dry_sand_rough", "dry_sand_deep", "transition")
    """Terrains (``gmloco.eval.mpm.window_terrain.terrain_cfg`` names: a medium, ``<medium>_rough``,
    ``<medium>_deep``, ``transition``)."""
    scenarios: tuple[Scenario, ...] = (Scenario.straight, Scenario.circle)
    seed: int = ranged(_interp("${seed}"), integer=True, ge=0, le=2**32 - 1)
    device: str | None = _interp("${device}")
    """The pipeline's device (``auto``: Warp's default, CUDA when present)."""
    gpus: list[int] = field(default_factory=list, metadata=each(integer=True, ge=0))
    """CUDA devices to spread the evaluation over: one process per GPU, each (terrain, scenario) cell split into one
    share per GPU, pooled into this stage's outputs (``gmloco.eval.g1.gpus``; the shares' folders under
    ``<out_dir>/cells``). Empty: one process on the pipeline's ``device``. One GPU steps ~110-130 robot-frames/s at
    the default setting: 100 walking episodes of a cell take ~26-30 minutes on one GPU (``BENCHMARKS.md``)."""


@dataclass
class AnalyzeLogsCfg(StageCfg):
    """MCAP robot-log analysis, ``gmloco.deploy.logs.analyze`` (issue 7)."""

    out_dir: str = _interp("${run_dir}/analyze_logs")
    inputs: list[str] = field(default_factory=lambda: ["${paths.sample_logs_dir}"])
    """MCAP files or folders of them (default: the committed sample recordings)."""
    include_run_recordings: bool = True
    """Also analyze every ``*.mcap`` that earlier stages wrote under the run directory."""
    figures: bool = True
    """Write the paper-style PNG figures."""


@dataclass
class MismatchCfg(StageCfg):
    """Sim-vs-real mismatch discovery, ``gmloco.deploy.mismatch`` (issue 8)."""

    out_dir: str = _interp("${run_dir}/mismatch")
    real: str = _interp("${paths.sample_logs_dir}/g1_scripted_rigid_no_odometry.mcap")
    """The "real" recording (MCAP, project schema); default: a committed sample recording."""
    duration_s: float | None = ranged(None, gt=0)
    """Analyze only the first ``duration_s`` seconds [s] (at least ~5 s); None: the whole recording."""
    horizon: int | None = ranged(None, integer=True, ge=1)
    """Shooting horizon of the replay [samples]; None: 60 ms at the recording's rate (30 samples at 500 Hz)."""
    ground: str = "plane"
    """Nominal ground of the replay: ``plane`` (rigid) or ``sand[:MATERIAL]`` (3D-RFT sand, material preset, default
    dry_sand), as ``gmloco-mismatch --ground``."""
    effects: list[str] | None = None
    """Effect ids to screen (``gmloco.deploy.mismatch.EFFECT_IDS``); None: the whole library."""
    n_boot: int = ranged(400, ge=1)
    """Block-bootstrap resamples of the attribution."""
    mirror_check: bool = True
    """Also test a left/right-swapped joint map."""
    plots: bool = True
    """Write the report's plots."""


@dataclass
class GranularEvalCfg(MaterialCellsCfg):
    """Evaluation of an exported policy in the granular training simulator (``gmloco.train.evaluate_policy``).

    The package's ``gmloco.train.evaluation_cells.MaterialCellsCfg`` (materials, speeds, repeats, episode duration,
    failure rules and floor of ``gmloco.train.EvalCfg``) with the pipeline's defaults and its smoke-scale sizes.
    """

    repeats: int = ranged(4, ge=1)
    """Envs per (material, speed) cell."""
    smoke_repeats: int = ranged(1, ge=1)
    """``repeats`` at smoke scale."""
    smoke_duration_s: float = ranged(0.5, gt=0)
    """``duration_s`` at smoke scale [s]."""


@dataclass
class SweepEvalCfg(GranularEvalCfg):
    """Evaluation of a trial's exported policy (``sweep.eval``), fixed for every trial of a study."""


@dataclass
class SweepCfg:
    """Optuna search over the train stage (``workflows/sweep.py``; ``docs/sweeps.md``)."""

    metric: str = MISSING
    """Objective: ``train_teacher/<metric>`` returned by the train stage (e.g. ``mean_reward``) or ``eval/<key>``
    of ``gmloco.train.evaluate_policy`` on the trial's exported policy (e.g. ``eval/all/vel_error``; PPO only)."""
    direction: str = "maximize"
    """``maximize`` or ``minimize``."""
    n_trials: int = ranged(20, ge=1)
    """Finished trials (complete, pruned or failed) the study should hold."""
    sampler_seed: int = ranged(_interp("${seed}"), integer=True, ge=0, le=2**32 - 1)
    """Seed of the TPE sampler (seeded samplers make sweeps reproducible)."""
    storage: str = ""
    """Where the study lives (``workflows/sweep_storage.py``). Empty: the embedded SQLite file ``<run_dir>/study.db``
    (one worker). An RDB URL (``postgresql+psycopg2://user@host:5432/db``) or ``journal:<file>``: a study that every
    worker started with the same command joins by ``study_name``, on any machine."""
    gpus: list[int] = field(default_factory=list, metadata=each(integer=True, ge=0))
    """CUDA devices of this machine, one worker process (one trial at a time) on each; ``device`` and
    ``train_teacher.gpus`` are set per worker. Empty: one worker on ``device``."""
    params: dict[str, Any] = field(default_factory=dict)
    """Search space: key -> ``{type: float|int|categorical, low, high, log, step, choices}``. Keys are the train
    section's config paths (``train_teacher.ppo.learning_rate``), the task's fields among them
    (``train_teacher.task.robot_dr.push_velocity``, with an index for range ends: ``train_teacher.task.material.mu_int.0``)."""
    study_name: str = _interp("${exp_name}")
    """Study name inside the storage."""
    experiment: str = "gm_loco"
    """Experiment swept when the command line has no ``+exp=``."""
    n_startup_trials: int = ranged(5, ge=0)
    """Random trials before the TPE sampler models the objective."""
    pruner_startup_trials: int = ranged(3, ge=0)
    """Trials that finish before the median pruner prunes anything."""
    pruner_warmup_steps: int = ranged(0, ge=0)
    """Training iterations of a trial before it may be pruned."""
    report_chunks: int = ranged(4, ge=1)
    """Training of a trial runs in this many resumed chunks; the objective is reported after each (pruning)."""
    fixed: dict[str, Any] = field(default_factory=dict)
    """Values set in every trial, by the same paths as ``params`` (``train_teacher.task.episode_length_s: 10``)."""
    eval: SweepEvalCfg = field(default_factory=SweepEvalCfg)
    """Evaluation used by ``eval/<key>`` objectives."""
    requeue_interrupted: bool = True
    """On start, mark trials left running by a killed or time-boxed call as failed and enqueue them again; the
    retry continues in the same trial folder from its newest checkpoint. Only for one worker per study."""
    smoke_trials: int = ranged(2, ge=1)
    """``n_trials`` at smoke scale."""
    smoke_fixed: dict[str, Any] = field(default_factory=lambda: {"train_teacher.task.episode_length_s": 0.1})
    """Extra ``fixed`` values at smoke scale, so that episodes finish within the few smoke steps."""
    trial_params: dict[str, Any] = field(default_factory=dict)
    """Set by the sweep in each trial's config: the trial number and its sampled values."""


class AblationSource(str, Enum):
    """Where the ablation's policies come from."""

    artifacts = "artifacts"
    """Committed ``artifacts/<exp>/policy.onnx`` (missing ones are reported missing)."""
    train = "train"
    """Train each experiment's train stage in ``<run_dir>/train/<exp>`` (time-boxed, resumable), then evaluate."""


@dataclass
class AblationCfg(GranularEvalCfg):
    """Contact-model ablation of vanilla PPO policies (``workflows/ablation.py``; ``docs/sweeps.md``).

    Every policy is scored by the same evaluation: the ``GranularEvalCfg`` fields at ``ablation.<field>``.
    """

    speeds: tuple[float, ...] = field(default=(0.5, 1.0), metadata=each(gt=0))
    """Commanded forward speeds [m/s]."""
    exps: list[str] = field(default_factory=lambda: ["ppo_rft3d", "ppo_heuristic_rft", "ppo_cone_multi", "ppo_rigid"])
    """Experiments compared (``conf/exp/<name>.yaml``)."""
    source: AblationSource = AblationSource.artifacts
    """Evaluate committed artifacts or train the experiments first."""
    artifacts_dir: str = _interp("${paths.root_dir}/artifacts")
    """Folder holding ``<exp>/policy.onnx``."""
    eval_contact_model: ContactModelName | None = ContactModelName.rft3d
    """Contact model of the simulator every policy is evaluated in (one ground for all); None: each policy's own."""
    terrain: TerrainName = TerrainName.flat
    """Sand terrain of the evaluation."""


@dataclass
class PipelineCfg:
    """Top-level config of ``full_pipeline.py`` and of every stage workflow."""

    exp_name: str = MISSING
    """Experiment name, set by ``+exp=<name>``; also the run directory's parent folder."""
    run_name: str = _interp("${now:%Y%m%d-%H%M%S}")
    """Run directory name; reuse it (or ``run_dir``) to resume."""
    run_dir: str = _interp("${paths.runs_dir}/${exp_name}/${run_name}")
    """The run directory (config, git state, manifest, stage outputs)."""
    seed: int = ranged(42, ge=0, le=2**32 - 1)
    """Seed given to ``seed_everything`` before any stage."""
    device: str = "auto"
    """``auto`` (cuda when available), ``cpu``, ``cuda`` or ``cuda:N``."""
    scale: ScaleName = ScaleName.full
    """Set by the ``scale`` group; ``smoke`` is applied automatically on a CPU-only machine."""
    max_minutes: float | None = ranged(None, gt=0)
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
    ablation: AblationCfg | None = None
    """Contact-model ablation settings, set by ``+ablation=<name>``; None outside ablations."""


def _writable(node: DictConfig) -> DictConfig:
    """Return ``node`` with the read-only flag cleared on every section.

    OmegaConf makes the node of a frozen dataclass (the eval package's configs are frozen values) read-only, which
    would refuse every YAML and command-line value; the section becomes the frozen dataclass again when a stage
    converts it (``OmegaConf.to_object``).
    """
    OmegaConf.set_readonly(node, False)
    for key in node:
        child = node._get_node(key)
        if isinstance(child, DictConfig) and not child._is_none():
            _writable(child)
    return node


def register_configs() -> None:
    """Register the schemas and the ``gmloco.repo_root`` resolver (idempotent)."""
    if not OmegaConf.has_resolver("gmloco.repo_root"):
        OmegaConf.register_new_resolver("gmloco.repo_root", lambda: str(REPO_ROOT))
    cs = ConfigStore.instance()
    cs.store(name="base_pipeline", node=_writable(OmegaConf.structured(PipelineCfg)))
    cs.store(group="paths", name="base_paths", node=PathsCfg)
    cs.store(group="tracking", name="base_tracking", node=TrackingCfg)
    cs.store(group="sweep", name="base_sweep", node=SweepCfg, package="sweep")
    cs.store(group="ablation", name="base_ablation", node=AblationCfg, package="ablation")


register_configs()
