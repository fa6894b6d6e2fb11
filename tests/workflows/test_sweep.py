# SPDX-License-Identifier: Apache-2.0
"""The Optuna sweep workflow (``workflows/sweep.py``): search space, task fields, study, pruning, resume, report.

The study machinery runs with the train stage's ``run_training`` replaced by a fake whose metric is a known
function of the trial's task (seconds); one ``slow`` test runs the real command at smoke scale on the CPU.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from omegaconf import DictConfig, OmegaConf

from tests.pipeline_helpers import run_cli
from workflows import policy_training, sweep, train_teacher
from workflows.stage_registry import StageIncompleteError
from workflows.stage_runner import PipelineConfigError

MU_KEY = "train_teacher.task.material.mu_int.0"
"""The searched DR range end in the fake-training tests."""
LR_KEY = "train_teacher.ppo.learning_rate"
"""A searched config override."""


class FakeTraining:
    """Stand-in for ``train_teacher.run_training``: writes a checkpoint; mean_reward = mu_int low end x iteration."""

    def __init__(self, interrupt_trial: int | None = None) -> None:
        """``interrupt_trial``: trial number whose first call stops at its time box (after one checkpoint)."""
        self.calls: list[dict[str, Any]] = []
        self.interrupt_trial = interrupt_trial

    def __call__(self, cfg: DictConfig, name: str, **kwargs: Any) -> dict[str, float]:
        """Record the call, write ``model_<iteration>.pt``, return the metrics ``train`` would."""
        section = cfg[name]
        out = Path(section.out_dir)
        out.mkdir(parents=True, exist_ok=True)
        if not section.resume:
            for p in out.glob("model_*.pt"):
                p.unlink()
        start = max((int(p.stem.split("_")[1]) for p in out.glob("model_*.pt")), default=0)
        number = int(cfg.sweep.trial_params["number"])
        task = kwargs["task"]
        self.calls.append(
            {
                "trial": number,
                "start": start,
                "end": int(section.max_iterations),
                "mu_low": task.material.mu_int[0],
                "lr": float(section.ppo.learning_rate),
                "episode_length_s": task.episode_length_s,
            }
        )
        if number == self.interrupt_trial and start == 0:
            (out / "model_1.pt").write_text("checkpoint")
            raise StageIncompleteError("time box reached at iteration 1")
        it = int(section.max_iterations)
        (out / f"model_{it}.pt").write_text("checkpoint")
        return {"iteration": float(it), "mean_reward": task.material.mu_int[0] * it}


@pytest.fixture
def fake_training(monkeypatch: pytest.MonkeyPatch) -> Callable[..., FakeTraining]:
    """Install a :class:`FakeTraining` (and a task factory that does not import mjlab)."""
    from gmloco.train.config import GranularTaskCfg

    monkeypatch.setattr(policy_training, "task_cfg", lambda section: _task(GranularTaskCfg(), section))

    def install(**kwargs: Any) -> FakeTraining:
        fake = FakeTraining(**kwargs)
        monkeypatch.setattr(train_teacher, "run_training", fake)
        return fake

    return install


def _task(task: Any, section: DictConfig) -> Any:
    """``task`` with the section's ``task`` fields set, as ``policy_training.task_cfg`` sets them."""
    from workflows.task_fields import apply_task_fields, flat_paths

    return apply_task_fields(task, flat_paths(section.get("task") or {}))


def _sweep_cfg(compose: Callable[..., DictConfig], run_dir: Path, n_trials: int) -> DictConfig:
    """The teacher sweep at smoke scale with a two-parameter space, 4 chunks of 8 iterations."""
    cfg = compose(
        "+exp=gm_loco",
        "+sweep=optuna_teacher",
        "+scale=smoke",
        f"run_dir={run_dir}",
        "device=cpu",
        "tracking.wandb=disabled",
        "train_teacher.max_iterations=8",
    )
    cfg.sweep.params = {
        MU_KEY: {"type": "float", "low": 0.1, "high": 0.4},
        LR_KEY: {"type": "float", "low": 3.0e-4, "high": 3.0e-3, "log": True},
    }
    cfg.sweep.smoke_trials = n_trials
    cfg.sweep.n_startup_trials = 2
    cfg.sweep.pruner_startup_trials = 1
    return cfg


def _load_study(run_dir: Path, storage: str = "") -> Any:
    """The study stored in the run directory (or in ``storage``)."""
    import optuna

    from workflows.sweep_storage import parse_storage

    return optuna.load_study(study_name="gm_loco", storage=parse_storage(storage, run_dir).open())


def test_parse_space_names_the_bad_entry() -> None:
    """Keys outside train_teacher., unknown types, low >= high and empty choices are refused by name."""
    bad = {
        "seed": {"type": "int", "low": 0, "high": 3},
        "train_teacher.task.action_scale": {"type": "uniform", "low": 0.1, "high": 0.3},
        MU_KEY: {"type": "float", "low": 0.4, "high": 0.1},
        "train_teacher.task.command_curriculum": {"type": "categorical", "choices": []},
    }
    for key, spec in bad.items():
        with pytest.raises(PipelineConfigError) as info:
            sweep.parse_space({key: spec})
        assert info.value.key == f"sweep.params.{key}"
    with pytest.raises(PipelineConfigError, match=r"write 'train_teacher\.task\.robot_dr\.push_velocity'"):
        sweep.parse_space({"task.robot_dr.push_velocity": {"type": "float", "low": 0, "high": 1}})
    key = "train_teacher.task.reward_ramp_steps"
    space = sweep.parse_space({key: {"type": "int", "low": 10, "high": 1000, "log": True}})
    assert space[0].distribution().log and space[0].distribution().low == 10


def test_check_space_catches_ranges_that_only_some_samples_empty(compose: Callable[..., DictConfig]) -> None:
    """mu_int low end searched up to 0.95 > the default high end 0.9: refused before any trial runs."""
    cfg = compose("+exp=gm_loco", "+sweep=optuna_teacher")
    space = sweep.parse_space({MU_KEY: {"type": "float", "low": 0.1, "high": 0.95}})
    from gmloco.train.config import GranularTaskCfg

    original = policy_training.task_cfg
    policy_training.task_cfg = lambda section: _task(GranularTaskCfg(), section)  # type: ignore[assignment]
    try:
        with pytest.raises(PipelineConfigError, match="low > high"):
            sweep.check_space(cfg, space, {})
        sweep.check_space(cfg, sweep.parse_space({MU_KEY: {"type": "float", "low": 0.1, "high": 0.9}}), {})
        with pytest.raises(
            PipelineConfigError, match=r"no key 'lr' in train_teacher\.ppo; valid keys: .*learning_rate"
        ):
            sweep.check_space(
                cfg, sweep.parse_space({"train_teacher.ppo.lr": {"type": "float", "low": 0, "high": 1}}), {}
            )
    finally:
        policy_training.task_cfg = original  # type: ignore[assignment]


def test_chunk_ends_split_the_iterations() -> None:
    """4 chunks of 10 iterations report at round(2.5)=2, 5, round(7.5)=8, 10; never more chunks than iterations."""
    assert sweep.chunk_ends(10, 4) == [2, 5, 8, 10]
    assert sweep.chunk_ends(2, 4) == [1, 2]
    assert sweep.chunk_ends(1, 4) == [1]


def test_objective_parse() -> None:
    """``train_teacher/<m>`` and ``eval/<key>`` parse; anything else is refused naming sweep.metric."""
    assert sweep.Objective.parse("eval/all/vel_error") == sweep.Objective("eval", "all/vel_error")
    assert sweep.Objective.parse("train_teacher/mean_reward").key == "mean_reward"
    with pytest.raises(PipelineConfigError) as info:
        sweep.Objective.parse("mean_reward")
    assert info.value.key == "sweep.metric"


def test_study_runs_trials_in_run_dirs_prunes_and_resumes(
    compose: Callable[..., DictConfig], fake_training: Callable[..., FakeTraining], tmp_path: Path
) -> None:
    """5 trials in their own run dirs, pruned by the median rule; a second call continues the study to 6.

    Each trial has its resolved config and git state in ``trials/<n>``; the sampled values reach the training; the
    summary matches the storage.
    """
    fake = fake_training()
    first_cfg = _sweep_cfg(compose, tmp_path, 5)
    first_cfg.sweep.n_startup_trials = 10  # random sampling throughout: the resume check below needs it
    summary = sweep.run_sweep(first_cfg)
    assert summary["exit_code"] == 0 and summary["finished"] == 5
    assert (tmp_path / "study.db").is_file() and (tmp_path / "config.yaml").is_file() and (tmp_path / "git").is_dir()
    rows = {r["number"]: r for r in summary["trials"]}
    assert sorted(rows) == list(range(5))
    for n, row in rows.items():
        trial_dir = tmp_path / f"trials/{n:04d}"
        assert row["run_dir"] == f"trials/{n:04d}"
        trial_cfg = OmegaConf.load(trial_dir / "config.yaml")
        assert trial_cfg.train_teacher.ppo.learning_rate == pytest.approx(row["params"][LR_KEY])
        assert trial_cfg.sweep.trial_params.number == n
        assert (trial_dir / "manifest.json").is_file() and (trial_dir / "git").is_dir()
        calls = [c for c in fake.calls if c["trial"] == n]
        assert all(c["mu_low"] == pytest.approx(row["params"][MU_KEY]) for c in calls)
        assert all(c["lr"] == pytest.approx(row["params"][LR_KEY]) for c in calls)
        assert all(c["episode_length_s"] == 0.1 for c in calls)  # smoke_fixed
        assert OmegaConf.select(trial_cfg, MU_KEY) == pytest.approx(row["params"][MU_KEY])
        # Chunks resume: each call starts where the previous one ended (8 iterations in 4 chunks).
        assert [(c["start"], c["end"]) for c in calls] == [(0, 2), (2, 4), (4, 6), (6, 8)][: len(calls)]
        reported = {int(k): v for k, v in row["intermediate"].items()}
        assert reported == {c["end"]: pytest.approx(c["mu_low"] * c["end"]) for c in calls}
        if row["state"] == "complete":
            assert row["value"] == pytest.approx(row["params"][MU_KEY] * 8) and len(calls) == 4
    states = summary["states"]
    assert states["pruned"] >= 1 and states["complete"] >= 2 and sum(states.values()) == 5
    assert all(len(r["intermediate"]) < 4 for r in rows.values() if r["state"] == "pruned")
    best = max((r for r in rows.values() if r["state"] == "complete"), key=lambda r: r["value"])
    assert summary["best"]["number"] == best["number"]
    assert _load_study(tmp_path).best_trial.number == best["number"]
    assert len((tmp_path / "trials.csv").read_text().splitlines()) == 6
    assert (tmp_path / "figures" / "sweep.png").stat().st_size > 10_000 and summary["figure"] == "sweep.png"
    # A second call continues the study to 6 trials; the first 5 are kept as they were.
    again_cfg = _sweep_cfg(compose, tmp_path, 6)
    again_cfg.sweep.n_startup_trials = 10
    again = sweep.run_sweep(again_cfg)
    assert again["finished"] == 6 and [r["number"] for r in again["trials"]] == list(range(6))
    assert [r["value"] for r in again["trials"][:5]] == [rows[n]["value"] for n in range(5)]
    # The resumed call does not repeat the first call's samples (its sampler seed is offset by the stored trials).
    assert len({r["params"][MU_KEY] for r in again["trials"]}) == 6


def test_time_box_interrupts_a_trial_and_the_next_call_continues_it(
    compose: Callable[..., DictConfig], fake_training: Callable[..., FakeTraining], tmp_path: Path
) -> None:
    """Trial 1 stops at its time box: exit 3; the rerun retries it in trials/0001 from its checkpoint."""
    fake = fake_training(interrupt_trial=1)
    first = sweep.run_sweep(_sweep_cfg(compose, tmp_path, 3))
    assert first["exit_code"] == 3 and first["finished"] == 1
    fake.interrupt_trial = None
    second = sweep.run_sweep(_sweep_cfg(compose, tmp_path, 3))
    assert second["exit_code"] == 0 and second["finished"] == 3
    retry = next(r for r in second["trials"] if r["retry_of"] == 1)
    assert retry["number"] == 2 and retry["run_dir"] == "trials/0001"
    fresh = next(r for r in second["trials"] if r["number"] == 3)
    assert fresh["params"] != retry["params"] and fresh["run_dir"] == "trials/0003"
    interrupted = [c for c in fake.calls if c["trial"] == 1]
    continued = [c for c in fake.calls if c["trial"] == 2]
    assert interrupted == [{**interrupted[0], "start": 0, "end": 2}]
    assert continued[0]["start"] == 1 and continued[0]["mu_low"] == interrupted[0]["mu_low"]
    assert 1 not in [r["number"] for r in second["trials"]]  # the interrupted attempt is not counted


def test_requeue_interrupted_retries_a_killed_trial(tmp_path: Path) -> None:
    """A trial left running by a killed call is failed and enqueued again with its values and folder."""
    import optuna
    from optuna.trial import TrialState

    study = optuna.create_study(storage=f"sqlite:///{tmp_path}/s.db", study_name="s")
    trial = study.ask({"x": optuna.distributions.FloatDistribution(0.0, 1.0)})
    trial.set_user_attr("run_dir", "trials/0000")
    trial.report(0.5, 3)
    assert sweep.requeue_interrupted(study) == [0]
    assert study.trials[0].state is TrialState.FAIL
    waiting = study.trials[1]
    assert waiting.state is TrialState.WAITING
    assert waiting.user_attrs == {"run_dir": "trials/0000", "retry_of": 0, "reports": [[3, 0.5]]}
    retried = study.ask({"x": optuna.distributions.FloatDistribution(0.0, 1.0)})
    assert retried.params == trial.params
    assert sweep.finished_trials(study) == []


def test_importances_rank_the_parameter_that_matters(compose: Callable[..., DictConfig]) -> None:
    """On f(x, y) = (x - 0.3)^2 (y unused), PED-ANOVA ranks x first; fewer than 5 complete trials give none."""
    import optuna

    study = optuna.create_study(sampler=optuna.samplers.RandomSampler(seed=0), direction="minimize")
    study.optimize(lambda t: (t.suggest_float("x", 0, 1) - 0.3) ** 2 + 0 * t.suggest_float("y", 0, 1), n_trials=40)
    found, why = sweep._importances(study, 40)
    assert found is not None and why == ""
    assert found["x"] > 0.8 and found["x"] > found["y"]
    assert sweep._importances(study, 4)[0] is None


@pytest.mark.parametrize(
    ("args", "key"),
    [
        (["+sweep=optuna_teacher", "sweep.metric=mean_reward"], "sweep.metric"),
        ([], "sweep"),
        (["+sweep=optuna_teacher", "sweep.storage=study.db"], "sweep.storage"),
        (["+sweep=optuna_teacher", "sweep.gpus=[0]", "device=cpu"], "sweep.gpus"),
        (
            ["+sweep=optuna_teacher", "sweep.fixed={train_teacher.task.material.mu_intt.0: 0.3}"],
            "train_teacher.task.material.mu_intt.0",
        ),
    ],
)
def test_bad_sweep_input_exits_2(tmp_path: Path, args: list[str], key: str) -> None:
    """A malformed metric or no +sweep= is one paragraph naming the key, exit code 2, nothing written."""
    res = run_cli(["workflows/sweep.py", *args, f"run_dir={tmp_path}", "+scale=smoke"], timeout=300)
    assert res.returncode == 2, res.stderr[-3000:]
    assert f"'{key}'" in res.stderr or f"{key}" in res.stderr
    assert not (tmp_path / "study.db").exists() and not (tmp_path / "config.yaml").exists()


def test_workers_join_a_shared_study_and_refuse_another_search(
    compose: Callable[..., DictConfig], fake_training: Callable[..., FakeTraining], tmp_path: Path
) -> None:
    """Two workers (run dirs) on one journal study; a worker with another search space is refused, exit code 2.

    The report has Optuna's optimization history and the best trial's resolved config.
    """
    fake_training()
    storage = f"journal:{tmp_path / 'shared.journal'}"
    first_cfg = _sweep_cfg(compose, tmp_path / "a", 2)
    first_cfg.sweep.storage = storage
    first = sweep.run_sweep(first_cfg)
    assert first["exit_code"] == 0 and first["finished"] == 2 and first["storage"] == storage
    assert not (tmp_path / "a" / "study.db").exists()
    second_cfg = _sweep_cfg(compose, tmp_path / "b", 3)
    second_cfg.sweep.storage = storage
    second = sweep.run_sweep(second_cfg)
    assert second["finished"] == 3 and sorted(r["run_dir"] for r in second["trials"])[-1] == "trials/0002"
    assert (tmp_path / "b" / "trials" / "0002").is_dir() and not (tmp_path / "b" / "trials" / "0000").exists()
    # Report: Optuna's figure and the best trial's config (rebuilt from its values wherever it ran).
    assert second["figures"] == ["optimization_history.png"]  # importances need 5 complete trials
    assert (tmp_path / "b" / "figures" / "optimization_history.png").stat().st_size > 5_000
    best = OmegaConf.load(tmp_path / "b" / second["best_config"])
    assert best.sweep.trial_params.number == second["best"]["number"]
    assert best.train_teacher.ppo.learning_rate == pytest.approx(second["best"]["params"][LR_KEY])
    # Another search on the same study name is refused (and so is another objective direction).
    other = _sweep_cfg(compose, tmp_path / "c", 4)
    other.sweep.storage = storage
    other.sweep.params[MU_KEY]["high"] = 0.3
    with pytest.raises(PipelineConfigError, match=r"sweep.params: study 'gm_loco' .*holds a different search"):
        sweep.run_sweep(other)
    res = run_cli(
        [
            "tests/workflows/sweep_fake_worker.py",
            "+sweep=optuna_teacher",
            "+scale=smoke",
            "device=cpu",
            f"run_dir={tmp_path / 'd'}",
            f"sweep.storage={storage}",
        ],
        timeout=300,
    )
    assert res.returncode == 2, res.stderr[-3000:]
    assert (
        "holds a different search" in res.stderr
        and "'train_teacher.task.robot_dr.push_velocity' only in this config" in res.stderr
    )


def test_gpu_workers_get_one_gpu_each(compose: Callable[..., DictConfig], tmp_path: Path) -> None:
    """``sweep.gpus=[0, 2]``: two worker configs on cuda:0 and cuda:2, each training on its GPU alone."""
    from workflows.sweep_workers import gpu_worker_cfgs

    cfg = compose("+exp=gm_loco", "+sweep=optuna_teacher", f"run_dir={tmp_path}", "sweep.gpus=[0,2]")
    cfg.train_teacher.gpus = [0, 1]
    workers = gpu_worker_cfgs(cfg)
    assert [w.device for w in workers] == ["cuda:0", "cuda:2"]
    assert [list(w.sweep.gpus) for w in workers] == [[0], [2]]
    assert all(list(w.train_teacher.gpus) == [] for w in workers) and list(cfg.sweep.gpus) == [0, 2]


def test_gpu_worker_processes_fill_one_study(
    compose: Callable[..., DictConfig], fake_training: Callable[..., FakeTraining], tmp_path: Path
) -> None:
    """Two spawned worker processes (as ``sweep.gpus`` starts, here on the CPU) run 4 distinct trials of one study."""
    from tests.workflows import sweep_fake_worker
    from workflows.sweep_workers import gpu_worker_cfgs, run_gpu_workers

    fake_training()
    cfg = _sweep_cfg(compose, tmp_path, 4)
    cfg.sweep.storage, cfg.sweep.gpus = f"journal:{tmp_path / 'study.journal'}", [0, 1]
    cfg.sweep.n_trials = 4  # what sweep._prepare makes of smoke_trials
    workers = gpu_worker_cfgs(cfg)
    for w in workers:
        w.device = "cpu"
    assert run_gpu_workers(workers, sweep_fake_worker.gpu_worker) == [0, 0]
    trials = _load_study(tmp_path, f"journal:{tmp_path / 'study.journal'}").trials
    assert 4 <= len(trials) <= 5 and all(t.state.is_finished() for t in trials)
    assert len({t.params[MU_KEY] for t in trials}) == len(trials)
    assert sorted(d.name for d in (tmp_path / "trials").iterdir()) == [f"{t.number:04d}" for t in trials]


@pytest.mark.slow
def test_sweep_command_runs_two_real_trials_on_cpu(tmp_path: Path) -> None:
    """``sweep.py +sweep=optuna_teacher`` on a CPU: smoke scale, 2 real trials, a summary, a CSV and a figure."""
    res = run_cli(["workflows/sweep.py", "+sweep=optuna_teacher", f"run_dir={tmp_path}", "device=cpu"], timeout=1200)
    assert res.returncode == 0, res.stderr[-4000:]
    summary = json.loads((tmp_path / "study_summary.json").read_text())
    assert summary["scale"] == "smoke" and summary["finished"] == 2
    assert summary["states"]["complete"] + summary["states"]["pruned"] == 2
    for row in summary["trials"]:
        assert (tmp_path / row["run_dir"] / "train_teacher" / "model_2.pt").is_file() or row["state"] == "pruned"
        assert len(row["intermediate"]) >= 1
    assert (tmp_path / "figures" / "sweep.png").is_file() and (tmp_path / "trials.csv").is_file()


def test_eval_objective_scores_each_chunk_on_the_fixed_evaluation(
    compose: Callable[..., DictConfig],
    fake_training: Callable[..., FakeTraining],
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
) -> None:
    """``eval/all/vel_error``: evaluate_policy runs on the chunk's policy.onnx with ``sweep.eval``; minimized."""
    import gmloco.train

    fake_training()
    monkeypatch.setattr(train_teacher, "vanilla_ppo_overrides", lambda section: {})
    calls: list[Any] = []

    def fake_evaluate(cfg: Any) -> dict[str, float]:
        """Velocity error = distance of the trial's mu_int low end from 0.25 (read from its resolved config)."""
        calls.append(cfg)
        trial_cfg = OmegaConf.load(Path(cfg.policy_path).parents[1] / "config.yaml")
        mu_low = trial_cfg.sweep.trial_params.params[MU_KEY]
        return {"all/vel_error": abs(mu_low - 0.25), "all/success_rate": 1.0}

    monkeypatch.setattr(gmloco.train, "evaluate_policy", fake_evaluate, raising=False)
    cfg = compose(
        "+exp=ppo_rft3d",
        "+sweep=optuna_ppo_dr",
        "+scale=smoke",
        f"run_dir={tmp_path}",
        "device=cpu",
        "tracking.wandb=disabled",
        "train_teacher.max_iterations=4",
    )
    cfg.sweep.params = {MU_KEY: {"type": "float", "low": 0.1, "high": 0.4}}
    cfg.sweep.smoke_trials = 3
    summary = sweep.run_sweep(cfg)
    assert summary["direction"] == "minimize" and summary["finished"] == 3
    for call in calls:
        assert call.materials == ("dry_sand", "poppy_seed") and call.speeds == (1.0,)
        assert (call.repeats, call.duration_s) == (1, 0.5)  # smoke_repeats, smoke_duration_s
        assert Path(call.policy_path).name == "policy.onnx" and Path(call.policy_path).parent.name == "train_teacher"
        assert Path(call.out_path).name.startswith("iteration_")
    for row in summary["trials"]:
        expected = abs(row["params"][MU_KEY] - 0.25)
        assert all(v == pytest.approx(expected) for v in row["intermediate"].values())
        if row["state"] == "complete":
            assert row["value"] == pytest.approx(expected)
    assert summary["best"]["value"] == min(r["value"] for r in summary["trials"] if r["state"] == "complete")


def test_eval_objective_is_refused_for_the_vae_teacher(compose: Callable[..., DictConfig], tmp_path: Path) -> None:
    """The teacher exports no ONNX policy, so an eval/ objective is bad input naming sweep.metric."""
    cfg = _sweep_cfg(compose, tmp_path, 2)
    cfg.sweep.metric = "eval/all/vel_error"
    with pytest.raises(PipelineConfigError) as info:
        sweep.run_sweep(cfg)
    assert info.value.key == "sweep.metric" and not (tmp_path / "config.yaml").exists()


def test_the_jump_task_is_refused(compose: Callable[..., DictConfig], tmp_path: Path) -> None:
    """``task.*`` paths address the velocity task, so a sweep of the jump task is bad input naming its key."""
    cfg = compose("+exp=jump_rft3d", "+sweep=optuna_teacher", f"run_dir={tmp_path}", "device=cpu")
    with pytest.raises(PipelineConfigError) as info:
        sweep.run_sweep(cfg)
    assert info.value.key == "train_teacher.jump" and not (tmp_path / "config.yaml").exists()


def test_trial_whose_training_finished_before_a_kill_reports_its_saved_metrics(
    compose: Callable[..., DictConfig], fake_training: Callable[..., FakeTraining], tmp_path: Path
) -> None:
    """All chunks already trained (checkpoint at max_iterations): no training call; train's metrics.json is used."""
    import optuna

    fake = fake_training()
    cfg = _sweep_cfg(compose, tmp_path, 2)
    cfg.run_dir = str(tmp_path)
    out = tmp_path / "train_teacher"
    out.mkdir()
    (out / "model_8.pt").write_text("checkpoint")
    (out / "metrics.json").write_text(json.dumps({"iteration": 8.0, "mean_reward": 1.5}))
    trial = optuna.create_study().ask()
    result = sweep.TrialStage(trial, sweep.Objective.parse("train_teacher/mean_reward"))(cfg)
    assert fake.calls == [] and result["objective"] == 1.5 and result["pruned"] == 0.0


def test_without_matplotlib_the_summary_is_written_and_the_figure_is_named_missing(
    compose: Callable[..., DictConfig],
    fake_training: Callable[..., FakeTraining],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """On a machine without matplotlib the study summary says the figure was not drawn; the sweep still succeeds."""
    import sys

    fake_training()
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # makes ``import matplotlib`` raise ImportError
    summary = sweep.run_sweep(_sweep_cfg(compose, tmp_path, 2))
    assert summary["exit_code"] == 0 and summary["figure"].startswith("not drawn: matplotlib is not installed")
    assert (tmp_path / "study_summary.json").is_file() and not (tmp_path / "figures" / "sweep.png").exists()
