# SPDX-License-Identifier: Apache-2.0
"""Optuna sweep over the train stage: domain-randomization ranges, curricula and PPO settings (``docs/sweeps.md``).

Usage::

    python workflows/sweep.py +sweep=optuna_teacher                        # gm_loco teacher; runs/gm_loco/<time>
    python workflows/sweep.py +sweep=optuna_ppo_dr max_minutes=9           # vanilla PPO-3D-RFT, eval objective
    python workflows/sweep.py +sweep=optuna_teacher run_dir=runs/gm_loco/<time>   # resume the study
    python workflows/sweep.py +sweep=optuna_teacher 'sweep.storage=postgresql+psycopg2://u:pw@host:5432/db'
    python workflows/sweep.py +sweep=optuna_teacher sweep.storage=journal:runs/s.journal 'sweep.gpus=[0,1]'

One study per run directory: ``study.db`` (SQLite, ``sweep.storage`` empty) with a seeded TPE sampler and a
median pruner; with ``sweep.storage=<RDB URL or journal:file>`` every worker that runs the same command, on any
machine, joins the study by name, and ``sweep.gpus=[0,1,...]`` runs one worker (one trial at a time) per GPU.
Each trial is the pipeline's train stage in its own run directory ``trials/<number>/`` (resolved config, git
state, manifest: ``pipeline_run.run_pipeline``) trained in ``sweep.report_chunks`` resumed chunks; after each chunk
the objective ``sweep.metric`` is reported to the pruner. A call stops at ``max_minutes``; a trial cut by the
time box (or by a kill) is enqueued again and continues from its checkpoint on the next call. The study is
summarized in ``study_summary.json``, ``trials.csv``, ``best_config.yaml`` (the best trial's resolved config) and
``figures/`` (``sweep.png``, Optuna's ``optimization_history.png`` and ``param_importances.png``).

Exit codes: 0 the study holds ``n_trials`` finished trials (at least one complete); 1 none completed; 2 bad input;
3 the time box was reached (rerun the same command with ``run_dir=`` to continue).
"""

from __future__ import annotations

import copy
import math
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf, open_dict

if not __package__:  # run as ``python workflows/<name>.py``: the checkout root makes ``workflows`` importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workflows.config_paths import path_problem
from workflows.manifest import StageStatus
from workflows.pipeline_report import console
from workflows.pipeline_run import EXIT_FAILED, EXIT_INCOMPLETE, EXIT_OK, run_pipeline
from workflows.run_dir import (
    atomic_write_json,
    atomic_write_text,
    atomic_write_yaml,
    read_json,
    seed_everything,
    write_git_state,
)
from workflows.schemas import REPO_ROOT
from workflows.section_cfg import field_values, section_as
from workflows.stage_registry import StageSpec
from workflows.stage_runner import PipelineConfigError, resolve_device
from workflows.sweep_storage import SweepStorage, parse_storage
from workflows.sweep_workers import (
    check_signature,
    claimed_trials,
    gpu_worker_cfgs,
    run_gpu_workers,
    signature,
)
from workflows.task_fields import TASK_SECTION, apply_task_fields

__all__ = ["Objective", "SearchParam", "main", "parse_space", "run_sweep"]

CONFIG_PREFIX = "train_teacher."
"""The config section a sweep may set (only the train stage runs in a trial)."""
TASK_PREFIX = f"{TASK_SECTION}."
"""Keys on ``gmloco.train.GranularTaskCfg`` (DR ranges, curricula), set by the train stage (``task_fields``)."""
PARAM_TYPES = ("float", "int", "categorical")
"""Search-space entry types."""
MIN_TRIALS_FOR_IMPORTANCE = 5
"""Complete trials before parameter importances are computed (fewer give numbers that mean nothing)."""


def _bad(key: str, message: str) -> PipelineConfigError:
    """An input error naming ``key`` (reported as one paragraph, exit code 2, by ``hydra_entry``)."""
    return PipelineConfigError(key, f"{key}: {message}")


# Search space.


@dataclass(frozen=True)
class SearchParam:
    """One entry of ``sweep.params``."""

    key: str
    """Config path (``train_teacher.ppo.learning_rate``, ``train_teacher.task.material.mu_int.0``)."""
    kind: str
    """``float``, ``int`` or ``categorical``."""
    low: float = 0.0
    """Lower bound (numeric kinds)."""
    high: float = 0.0
    """Upper bound (numeric kinds)."""
    log: bool = False
    """Sample on a log scale."""
    step: float | None = None
    """Grid step (numeric kinds); None: continuous / 1 for int."""
    choices: tuple[Any, ...] = ()
    """Values of a categorical entry."""

    def distribution(self) -> Any:
        """Return the Optuna distribution."""
        import optuna.distributions as od

        if self.kind == "categorical":
            return od.CategoricalDistribution(self.choices)
        if self.kind == "int":
            return od.IntDistribution(int(self.low), int(self.high), log=self.log, step=int(self.step or 1))
        return od.FloatDistribution(self.low, self.high, log=self.log, step=self.step)

    def extremes(self) -> tuple[Any, Any]:
        """The two most extreme values (range ends are checked with them)."""
        return (self.choices[0], self.choices[-1]) if self.kind == "categorical" else (self.low, self.high)


def parse_space(params: Mapping[str, Any]) -> list[SearchParam]:
    """Parse ``sweep.params``; raise :class:`PipelineConfigError` naming the first bad entry."""
    space = []
    for key, spec in params.items():
        where = f"sweep.params.{key}"
        if str(key).startswith("task."):
            raise _bad(where, f"the task's fields sit at '{TASK_PREFIX}<path>': write '{CONFIG_PREFIX}{key}'.")
        if not str(key).startswith(CONFIG_PREFIX):
            raise _bad(where, f"search key must start with '{CONFIG_PREFIX}' (the train stage's section).")
        kind = str(spec.get("type", ""))
        if kind not in PARAM_TYPES:
            raise _bad(where, f"type must be one of {', '.join(PARAM_TYPES)}, got '{kind}'.")
        if kind == "categorical":
            choices = tuple(spec.get("choices") or ())
            if not choices:
                raise _bad(where, "a categorical entry needs a non-empty 'choices' list.")
            space.append(SearchParam(str(key), kind, choices=choices))
            continue
        if "low" not in spec or "high" not in spec or float(spec["low"]) >= float(spec["high"]):
            raise _bad(where, f"a {kind} entry needs 'low' < 'high'.")
        step = spec.get("step")
        log = bool(spec.get("log", False))
        space.append(SearchParam(str(key), kind, float(spec["low"]), float(spec["high"]), log, step))
    return space


def _bad_path(node: Any, path: str, key: str, prefix: str = "") -> None:
    """Raise when ``path`` names no key of ``node``; the message lists the valid keys of the section it left."""
    if (problem := path_problem(node, path, prefix)) is not None:
        raise _bad(key, problem)


def check_space(cfg: DictConfig, space: Sequence[SearchParam], fixed: Mapping[str, Any]) -> None:
    """Check every key before the first trial: config keys exist; task paths exist; no range can become empty."""
    keys = [(p.key, f"sweep.params.{p.key}") for p in space] + [(str(k), f"sweep.fixed.{k}") for k in fixed]
    for key, where in keys:
        if not key.startswith(CONFIG_PREFIX):
            raise _bad(where, f"key must start with '{CONFIG_PREFIX}' (the train stage's section).")
        if not key.startswith(TASK_PREFIX):
            _bad_path(cfg, key, where)
    task_params = [p for p in space if p.key.startswith(TASK_PREFIX)]
    task_fixed = {k.removeprefix(TASK_PREFIX): v for k, v in fixed.items() if k.startswith(TASK_PREFIX)}
    if not task_params and not task_fixed:
        return
    from workflows.policy_training import task_cfg

    base = task_cfg(cfg.train_teacher)
    # Worst case for a range: its low end at its largest value and its high end at its smallest.
    worst = {p.key.removeprefix(TASK_PREFIX): p.extremes()[1 if p.key.endswith(".0") else 0] for p in task_params}
    high = {p.key.removeprefix(TASK_PREFIX): p.extremes()[1] for p in task_params}
    apply_task_fields(base, {**task_fixed, **worst})
    apply_task_fields(base, {**task_fixed, **high})


# Objective.


@dataclass(frozen=True)
class Objective:
    """The optimized metric: ``train_teacher/<metric>`` of the train stage or ``eval/<key>`` of ``evaluate_policy``."""

    source: str
    """``train_teacher`` or ``eval``."""
    key: str
    """Metric name within the source."""

    @classmethod
    def parse(cls, metric: str) -> Objective:
        """Parse ``sweep.metric``."""
        source, _, key = str(metric).partition("/")
        if source not in ("train_teacher", "eval") or not key:
            raise _bad("sweep.metric", f"metric '{metric}' must be 'train_teacher/<metric>' or 'eval/<key>'.")
        return cls(source, key)

    def value(self, cfg: DictConfig, metrics: Mapping[str, Any]) -> float | None:
        """The objective after a training chunk (None when undefined, e.g. no episode finished yet)."""
        if self.source == "eval":
            metrics = self._evaluate(cfg, int(metrics["iteration"]))
        value = metrics.get(self.key)
        if value is None and self.source == "eval":
            raise KeyError(f"evaluate_policy returned no '{self.key}'; keys: {', '.join(sorted(metrics))}")
        return float(value) if value is not None and math.isfinite(float(value)) else None

    def _evaluate(self, cfg: DictConfig, iteration: int) -> dict[str, float]:
        """Roll out the chunk's exported ``policy.onnx`` on the fixed materials of ``sweep.eval``."""
        from gmloco.train import EvalCfg, evaluate_policy
        from gmloco.train.evaluation_cells import MaterialCellsCfg
        from workflows.policy_training import torch_device

        section, out = cfg.train_teacher, Path(cfg.train_teacher.out_dir)
        cells = section_as(MaterialCellsCfg, cfg.sweep.eval)
        return evaluate_policy(
            EvalCfg(
                **field_values(cells),
                policy_path=str(out / "policy.onnx"),
                terrain=str(section.terrain.value),  # type: ignore[arg-type]
                device=torch_device(str(cfg.device)),
                seed=int(cfg.seed),
                out_path=str(out / "eval" / f"iteration_{iteration}.json"),
            )
        )


# One trial.


def chunk_ends(total: int, chunks: int) -> list[int]:
    """Iteration counts at which the objective is reported: ``chunks`` near-equal parts of ``total``."""
    n = max(1, min(int(chunks), int(total)))
    return sorted({round(total * (k + 1) / n) for k in range(n)})


class TrialStage:
    """The train stage of one trial: chunked, resumed training; the objective goes to the pruner after each chunk."""

    def __init__(self, trial: Any, objective: Objective) -> None:
        """Bind the Optuna trial and the objective."""
        self.trial, self.objective = trial, objective
        self.pruned = False
        for step, value in trial.user_attrs.get("reports", []):  # reports of the interrupted run it continues
            trial.report(float(value), int(step))

    def __call__(self, cfg: DictConfig) -> dict[str, Any]:
        """Train chunk by chunk (``StageRunner`` passes ``resume`` and ``max_minutes``); return the metrics."""
        from workflows import train_teacher
        from workflows.policy_training import newest_checkpoint, task_cfg

        section = cfg.train_teacher
        task = task_cfg(section)  # the trial's train_teacher.task values included
        deadline = None if section.max_minutes is None else time.monotonic() + 60.0 * float(section.max_minutes)
        done = _checkpoint_iteration(newest_checkpoint, section.out_dir) if section.resume else 0
        metrics: dict[str, Any] = {}
        value = None
        for k, end in enumerate(chunk_ends(int(section.max_iterations), int(cfg.sweep.report_chunks))):
            if end <= done:
                continue
            chunk = copy.deepcopy(cfg)
            chunk.train_teacher.max_iterations = end
            chunk.train_teacher.resume = bool(section.resume) or k > 0
            if deadline is not None:
                chunk.train_teacher.max_minutes = max(0.0, (deadline - time.monotonic()) / 60.0)
            metrics = train_teacher.run(chunk, task)
            value = self.objective.value(chunk, metrics)
            if value is not None:
                self.trial.report(value, int(metrics["iteration"]))
                if self.trial.should_prune():
                    self.pruned = True
                    break
        if not metrics:  # killed after its last chunk trained but before the report: that chunk's metrics
            metrics = read_json(Path(section.out_dir) / "metrics.json", default={}) or {}
            value = self.objective.value(cfg, metrics) if "iteration" in metrics else None
        return {**metrics, "objective": value, "pruned": float(self.pruned)}


def _checkpoint_iteration(newest: Any, folder: str) -> int:
    """Iteration of the newest checkpoint in ``folder`` (0 without one)."""
    try:
        return int(newest(folder).stem.split("_")[1])
    except FileNotFoundError:
        return 0


@dataclass
class TrialOutcome:
    """How one trial ended."""

    state: str
    """``complete``, ``pruned``, ``fail`` or ``interrupted``."""
    value: float | None
    """Objective (complete trials) or last reported value (pruned)."""
    message: str = ""
    """Why it failed or was interrupted."""


def _trial_cfg(cfg: DictConfig, trial: Any, trial_dir: Path, deadline: float | None) -> DictConfig:
    """The trial's pipeline config: ``sweep.fixed``, then the trial's values, each set at its config path."""
    tcfg = copy.deepcopy(cfg)
    tcfg.run_name, tcfg.run_dir, tcfg.stages = trial_dir.name, str(trial_dir), ["train_teacher"]
    with open_dict(tcfg.train_teacher.task):  # the task's fields: an open mapping, its paths checked by check_space
        for key, value in {**cfg.sweep.fixed, **trial.params}.items():
            OmegaConf.update(tcfg, str(key), value, merge=True)
    tcfg.sweep.trial_params = {"number": trial.number, "params": dict(trial.params)}
    if deadline is not None:
        tcfg.max_minutes = max(0.0, (deadline - time.monotonic()) / 60.0)
    return tcfg


def run_trial(cfg: DictConfig, trial: Any, objective: Objective, root: Path, deadline: float | None) -> TrialOutcome:
    """Run one trial's train stage through the pipeline in ``trials/<number>`` (or the folder it continues)."""
    trial_dir = root / str(trial.user_attrs.get("run_dir", f"trials/{trial.number:04d}"))
    trial.set_user_attr("run_dir", trial_dir.relative_to(root).as_posix())
    tcfg = _trial_cfg(cfg, trial, trial_dir, deadline)
    stage = TrialStage(trial, objective)
    spec = StageSpec("train_teacher", (4, 6), (), f"sweep trial {trial.number}", fn=stage)
    row = run_pipeline(tcfg, registry=(spec,), run_dir=str(trial_dir))["stages"][0]
    status, metrics = StageStatus(row["status"]), row["metrics"]
    if status in (StageStatus.INCOMPLETE, StageStatus.DEFERRED):
        return TrialOutcome("interrupted", None, row["message"])
    if status is StageStatus.FAILED:
        return TrialOutcome("fail", None, row["message"])
    value = metrics.get("objective")
    if metrics.get("pruned"):
        return TrialOutcome("pruned", value)
    if value is None:
        return TrialOutcome("fail", None, f"objective {cfg.sweep.metric} undefined (e.g. no episode finished)")
    return TrialOutcome("complete", float(value))


# The study.


def _prepare(cfg: DictConfig) -> DictConfig:
    """Copy ``cfg``, pin run dir / device, apply the smoke limits; check the sweep's input."""
    if cfg.get("sweep") is None:
        from workflows.config_errors import group_options

        raise _bad("sweep", f"no sweep chosen: add +sweep=<name>. Valid choices: {', '.join(group_options('sweep'))}.")
    cfg = copy.deepcopy(cfg)
    cfg.run_name, cfg.run_dir = str(cfg.run_name), str(Path(cfg.run_dir).resolve())
    cfg.device = resolve_device(str(cfg.device))
    cfg.stages = ["train_teacher"]
    if str(cfg.sweep.direction) not in ("maximize", "minimize"):
        raise _bad("sweep.direction", f"direction must be 'maximize' or 'minimize', got '{cfg.sweep.direction}'.")
    parse_storage(str(cfg.sweep.storage), Path(cfg.run_dir))
    _check_gpus(cfg)
    if len(cfg.sweep.gpus) == 1:
        cfg = gpu_worker_cfgs(cfg)[0]
    if str(getattr(cfg.scale, "value", cfg.scale)) == "smoke":
        cfg.sweep.n_trials = min(int(cfg.sweep.n_trials), int(cfg.sweep.smoke_trials))
        cfg.sweep.fixed = {**cfg.sweep.fixed, **cfg.sweep.smoke_fixed}
        ev = cfg.sweep.eval
        ev.repeats, ev.duration_s = ev.smoke_repeats, ev.smoke_duration_s
        console.print(f"[yellow]sweep at smoke scale: {cfg.sweep.n_trials} trials, fixed {cfg.sweep.smoke_fixed}")
    return cfg


def _check_gpus(cfg: DictConfig) -> None:
    """``sweep.gpus`` must name distinct CUDA devices of this machine."""
    gpus = [int(g) for g in cfg.sweep.gpus]
    if not gpus:
        return
    from gmloco.train.multi_gpu import cuda_device_count, gpus_problem

    if (problem := gpus_problem(gpus, cuda_device_count())) is not None:
        raise _bad("sweep.gpus", f"bad value {gpus}: {problem}.")


def _create_study(cfg: DictConfig, storage: SweepStorage, space: Sequence[SearchParam], worker: bool) -> Any:
    """Create or join the study: seeded TPE sampler, median pruner over training iterations, same search.

    ``worker``: one of several processes sampling the study at once (a shared storage or ``sweep.gpus``).
    """
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    sweep = cfg.sweep
    study = optuna.create_study(
        study_name=str(sweep.study_name),
        storage=storage.open(),
        pruner=optuna.pruners.MedianPruner(
            n_startup_trials=int(sweep.pruner_startup_trials), n_warmup_steps=int(sweep.pruner_warmup_steps)
        ),
        direction="maximize" if str(sweep.direction) == "maximize" else "minimize",
        load_if_exists=True,
    )
    check_signature(study, signature(str(sweep.metric), str(sweep.direction), _distributions(space)), storage.display())
    # The sampler's RNG lives in this process: a resumed call seeded like the first would repeat its samples, so
    # the seed is offset by the trials already stored (still reproducible from the study's history).
    seed = int(sweep.sampler_seed) + len(study.get_trials(deepcopy=False))
    if worker:  # workers seeded alike would propose the same values: each adds its host and process id
        import os
        import socket
        import zlib

        seed = zlib.crc32(f"{seed}:{socket.gethostname()}:{os.getpid()}".encode())
    study.sampler = optuna.samplers.TPESampler(seed=seed, n_startup_trials=int(sweep.n_startup_trials))
    return study


def _retry(study: Any, trial: Any) -> None:
    """Fail an interrupted trial and enqueue its values again, to continue in the same folder."""
    from optuna.trial import TrialState

    reports = sorted([int(s), float(v)] for s, v in trial.intermediate_values.items())
    attrs = {"run_dir": trial.user_attrs.get("run_dir"), "retry_of": trial.number, "reports": reports}
    study.tell(trial.number, state=TrialState.FAIL, skip_if_finished=True)
    study.enqueue_trial(dict(trial.params), user_attrs={k: v for k, v in attrs.items() if v is not None})


def _distributions(space: Sequence[SearchParam]) -> dict[str, Any]:
    """Optuna distribution of each searched key."""
    return {p.key: p.distribution() for p in space}


def requeue_interrupted(study: Any) -> list[int]:
    """Fail and re-enqueue every running trial (left by a killed call; one worker per study assumed)."""
    from optuna.trial import TrialState

    running = study.get_trials(deepcopy=False, states=(TrialState.RUNNING,))
    for t in running:
        _retry(study, t)
    return [t.number for t in running]


def finished_trials(study: Any) -> list[Any]:
    """Complete, pruned and failed trials, without those that were interrupted and retried."""
    from optuna.trial import TrialState

    trials = study.get_trials(deepcopy=False)
    retried = {t.user_attrs.get("retry_of") for t in trials}
    done = (TrialState.COMPLETE, TrialState.PRUNED, TrialState.FAIL)
    return [t for t in trials if t.state in done and t.number not in retried]


def _tell(study: Any, trial: Any, outcome: TrialOutcome) -> None:
    """Record the outcome in the study."""
    from optuna.trial import TrialState

    trial.set_user_attr("message", outcome.message)
    if outcome.state == "interrupted":
        _retry(study, study.trials[trial.number])
    elif outcome.state == "complete":
        study.tell(trial, outcome.value)
    else:
        study.tell(trial, state=TrialState.PRUNED if outcome.state == "pruned" else TrialState.FAIL)


def _space(cfg: DictConfig) -> list[SearchParam]:
    """The parsed ``sweep.params``."""
    params = OmegaConf.to_container(cfg.sweep.params, resolve=True)
    assert isinstance(params, dict)
    return parse_space({str(k): v for k, v in params.items()})


def _setup(cfg: DictConfig) -> tuple[Path, Objective, list[SearchParam], dict[str, Any]]:
    """Check the objective and search space, then seed and write the sweep's resolved config and git state."""
    objective = Objective.parse(str(cfg.sweep.metric))
    if cfg.train_teacher.get("jump") is not None:
        raise _bad("train_teacher.jump", "the sweep searches the velocity task (GranularTaskCfg), not the jump task.")
    if objective.source == "eval" and cfg.train_teacher.algorithm.value != "ppo":
        raise _bad(
            "sweep.metric", "eval/<key> objectives need a policy.onnx: only train_teacher.algorithm=ppo exports one."
        )
    space = _space(cfg)
    check_space(cfg, space, {str(k): v for k, v in cfg.sweep.fixed.items()})
    seed_everything(int(cfg.seed))
    root = Path(cfg.run_dir)
    atomic_write_yaml(root / "config.yaml", OmegaConf.to_container(cfg, resolve=True, enum_to_str=True))
    return root, objective, space, write_git_state(REPO_ROOT, root)


def run_sweep(cfg: DictConfig) -> dict[str, Any]:
    """Run (or continue) the study until it holds ``sweep.n_trials`` finished trials or the time box is reached.

    Returns:
        The study summary also written to ``<run_dir>/study_summary.json``, with ``exit_code``.
    """
    cfg = _prepare(cfg)
    root, objective, space, git = _setup(cfg)
    storage = parse_storage(str(cfg.sweep.storage), root)
    study = _create_study(cfg, storage, space, worker=storage.shared)
    # Running trials of a shared study may belong to live workers elsewhere: only a lone worker requeues them.
    if cfg.sweep.requeue_interrupted and not storage.shared and (requeued := requeue_interrupted(study)):
        console.print(f"continuing interrupted trials {requeued} from their checkpoints")
    if len(cfg.sweep.gpus) > 1:
        console.print(f"one worker per GPU: {list(cfg.sweep.gpus)}")
        timed_out = EXIT_INCOMPLETE in run_gpu_workers(gpu_worker_cfgs(cfg), _gpu_worker)
    else:
        timed_out = _work(cfg, study, objective, space, root)
    n_complete = sum(t.state.name == "COMPLETE" for t in finished_trials(study))
    code = EXIT_INCOMPLETE if timed_out else (EXIT_OK if n_complete else EXIT_FAILED)
    summary = write_report(study, cfg, root, git, finished_trials(study), code)
    console.print(f"study summary: {root / 'study_summary.json'} (best: {summary['best']})")
    if code == EXIT_INCOMPLETE:
        console.print(f"resume: rerun the same command with run_dir={root}")
    return summary


def _gpu_worker(cfg: DictConfig) -> int:
    """One GPU's worker process of ``sweep.gpus``: join the study, run trials; exit 3 at the time box, else 0."""
    root = Path(cfg.run_dir)
    space = _space(cfg)
    study = _create_study(cfg, parse_storage(str(cfg.sweep.storage), root), space, worker=True)
    timed_out = _work(cfg, study, Objective.parse(str(cfg.sweep.metric)), space, root)
    return EXIT_INCOMPLETE if timed_out else EXIT_OK


def _work(cfg: DictConfig, study: Any, objective: Objective, space: Sequence[SearchParam], root: Path) -> bool:
    """Ask, run and tell trials until the study holds ``n_trials`` finished or running ones; True at the time box."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    deadline = None if cfg.max_minutes is None else time.monotonic() + 60.0 * float(cfg.max_minutes)
    distributions = _distributions(space)
    total, timed_out = int(cfg.sweep.n_trials), False
    columns = (TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=console) as progress:
        bar = progress.add_task("sweep", total=total, completed=min(total, len(finished_trials(study))))
        while claimed_trials(study, finished_trials(study)) < total:
            if deadline is not None and time.monotonic() >= deadline:
                timed_out = True
                break
            trial = study.ask(distributions)
            progress.update(bar, description=f"sweep: trial {trial.number}")
            outcome = run_trial(cfg, trial, objective, root, deadline)
            _tell(study, trial, outcome)
            progress.console.print(
                f"  trial {trial.number}: {outcome.state} {outcome.value} {outcome.message}".rstrip()
            )
            timed_out = outcome.state == "interrupted"
            progress.update(bar, completed=min(total, len(finished_trials(study))))
            if timed_out:
                break
    return timed_out


# Report: study_summary.json, trials.csv, figures/sweep.png.


def _trial_row(t: Any) -> dict[str, Any]:
    """One finished trial as a JSON-ready dict."""
    return {
        "number": t.number,
        "state": t.state.name.lower(),
        "value": t.value,
        "params": dict(t.params),
        "intermediate": {str(k): v for k, v in sorted(t.intermediate_values.items())},
        "run_dir": t.user_attrs.get("run_dir"),
        "retry_of": t.user_attrs.get("retry_of"),
        "message": t.user_attrs.get("message", ""),
        "duration_s": None if t.duration is None else t.duration.total_seconds(),
    }


def _importances(study: Any, n_complete: int) -> tuple[dict[str, float] | None, str]:
    """PED-ANOVA parameter importances (no scikit-learn needed), or None and the reason."""
    import optuna

    if n_complete < MIN_TRIALS_FOR_IMPORTANCE or not study.best_trial.params:
        return None, f"needs {MIN_TRIALS_FOR_IMPORTANCE} complete trials with parameters (has {n_complete})"
    try:
        evaluator = optuna.importance.PedAnovaImportanceEvaluator()
        found = optuna.importance.get_param_importances(study, evaluator=evaluator)
    except (RuntimeError, ValueError) as e:
        return None, f"{type(e).__name__}: {e}"
    return {k: float(v) for k, v in found.items()}, ""


def _write_csv(path: Path, rows: Sequence[dict[str, Any]]) -> None:
    """One line per finished trial: number, state, value, run_dir, then one column per parameter."""
    import csv
    import io

    keys = sorted({k for r in rows for k in r["params"]})
    buf = io.StringIO()
    writer = csv.writer(buf)
    writer.writerow(["number", "state", "value", "run_dir", *keys])
    for r in rows:
        writer.writerow([r["number"], r["state"], r["value"], r["run_dir"], *(r["params"].get(k) for k in keys)])
    atomic_write_text(path, buf.getvalue())


def _figure(
    path: Path, rows: Sequence[dict[str, Any]], importances: dict[str, float] | None, why: str, cfg: Any
) -> None:
    """Optimization history (objective and best so far), intermediate values per trial, parameter importances."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_h, ax_i, ax_p) = plt.subplots(1, 3, figsize=(15, 4.2))
    better = max if str(cfg.sweep.direction) == "maximize" else min
    done = [r for r in rows if r["state"] == "complete"]
    best, best_so_far = None, []
    for r in done:
        best = r["value"] if best is None else better(best, r["value"])
        best_so_far.append(best)
    ax_h.plot([r["number"] for r in done], [r["value"] for r in done], "o", label="complete")
    ax_h.step([r["number"] for r in done], best_so_far, where="post", label="best so far")
    pruned = [r for r in rows if r["state"] == "pruned" and r["intermediate"]]
    ax_h.plot(
        [r["number"] for r in pruned], [list(r["intermediate"].values())[-1] for r in pruned], "x", label="pruned"
    )
    ax_h.set(xlabel="trial", ylabel=str(cfg.sweep.metric), title="optimization history")
    ax_h.legend(fontsize=8)
    for r in rows:
        steps = [int(k) for k in r["intermediate"]]
        ax_i.plot(steps, list(r["intermediate"].values()), "-o", ms=3, label=f"{r['number']} ({r['state']})")
    ax_i.set(xlabel="training iteration", ylabel=str(cfg.sweep.metric), title="reported values (median pruner)")
    if len(rows) <= 12:
        ax_i.legend(fontsize=7)
    if importances:
        names = list(importances)[::-1]
        ax_p.barh(names, [importances[n] for n in names])
        ax_p.set(xlabel="importance (PED-ANOVA)", title="parameter importance")
    else:
        ax_p.text(0.5, 0.5, f"no importances:\n{why}", ha="center", va="center", wrap=True, fontsize=9)
        ax_p.set_axis_off()
    fig.suptitle(f"{cfg.sweep.study_name}: {len(done)} complete of {len(rows)} finished trials")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _figure_or_note(path: Path, *args: Any) -> str:
    """Draw ``figures/sweep.png`` and return its name, or say why not (the GPU image may lack matplotlib)."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return "not drawn: matplotlib is not installed; rerun the same command where it is to draw it"
    _figure(path, *args)
    return path.name


def _write_best_config(cfg: DictConfig, root: Path, trials: Sequence[Any], best: dict | None) -> str | None:
    """Write the best trial's resolved config (as its trial folder has it) to ``best_config.yaml``; its name."""
    if best is None:
        return None
    trial = next(t for t in trials if t.number == best["number"])
    trial_dir = root / str(trial.user_attrs.get("run_dir", f"trials/{trial.number:04d}"))
    tcfg = _trial_cfg(cfg, trial, trial_dir, None)
    atomic_write_yaml(root / "best_config.yaml", OmegaConf.to_container(tcfg, resolve=True, enum_to_str=True))
    return "best_config.yaml"


def write_report(
    study: Any, cfg: DictConfig, root: Path, git: dict[str, Any], trials: Sequence[Any], code: int
) -> dict:
    """Write ``study_summary.json``, ``trials.csv`` and ``figures/sweep.png``; return the summary."""
    rows = [_trial_row(t) for t in trials]
    done = [r for r in rows if r["state"] == "complete"]
    better = max if str(cfg.sweep.direction) == "maximize" else min
    best = better(done, key=lambda r: r["value"]) if done else None
    importances, why = _importances(study, len(done))
    states = {s: sum(r["state"] == s for r in rows) for s in ("complete", "pruned", "fail")}
    summary = {
        "study_name": str(cfg.sweep.study_name),
        "storage": parse_storage(str(cfg.sweep.storage), root).display(),
        "metric": str(cfg.sweep.metric),
        "direction": str(cfg.sweep.direction),
        "n_trials": int(cfg.sweep.n_trials),
        "finished": len(rows),
        "states": states,
        "best": None if best is None else {k: best[k] for k in ("number", "value", "params", "run_dir")},
        "importances": importances,
        "importances_note": why,
        "search_space": OmegaConf.to_container(cfg.sweep.params, resolve=True),
        "fixed": OmegaConf.to_container(cfg.sweep.fixed, resolve=True),
        "scale": str(getattr(cfg.scale, "value", cfg.scale)),
        "device": str(cfg.device),
        "seed": int(cfg.seed),
        "git_commit": git["commit"],
        "trials": rows,
        "exit_code": code,
    }
    summary["figure"] = _figure_or_note(root / "figures" / "sweep.png", rows, importances, why, cfg)
    if summary["figure"] == "sweep.png":
        from workflows.sweep_figures import write_optuna_figures

        summary["figures"] = write_optuna_figures(study, root / "figures", importances is not None)
    summary["best_config"] = _write_best_config(cfg, root, trials, best)
    atomic_write_json(root / "study_summary.json", summary)
    _write_csv(root / "trials.csv", rows)
    return summary


def _defaults(argv: Sequence[str]) -> list[str]:
    """Add ``+exp=<sweep.experiment>`` and ``run_dir=<runs>/<exp>/sweep-<time>`` when the command line has none."""
    args = list(argv)
    if not any(a.startswith(("run_dir=", "run_name=")) for a in args):
        args.insert(0, "run_dir=${paths.runs_dir}/${exp_name}/sweep-${run_name}")
    if any(a.lstrip("+").startswith("exp=") for a in argv):
        return args
    from workflows.config_errors import CONF_DIR
    from workflows.schemas import SweepCfg

    names = [a.split("=", 1)[1] for a in argv if a.lstrip("+").startswith("sweep=")]
    path = CONF_DIR / "sweep" / f"{names[0]}.yaml" if names else None
    exp = SweepCfg.experiment
    loaded = OmegaConf.load(path) if path is not None and path.is_file() else None
    if isinstance(loaded, DictConfig):
        exp = str(loaded.get("experiment", exp))
    return [f"+exp={exp}", *args]


def _task(cfg: DictConfig) -> int:
    """Hydra task body: run the sweep, return its exit code."""
    return int(run_sweep(cfg)["exit_code"])


def main() -> None:
    """Command-line entry (Hydra)."""
    from workflows.hydra_entry import hydra_entry

    sys.argv = [sys.argv[0], *_defaults(sys.argv[1:])]
    hydra_entry(_task, only_stage="train_teacher")


if __name__ == "__main__":
    main()
