# SPDX-License-Identifier: Apache-2.0
"""Skip, resume, force and failure handling of the pipeline, exercised with two toy stages in-process."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from omegaconf import DictConfig

from tests.pipeline_helpers import CALLS, toy_registry, toy_teacher
from workflows.pipeline_run import EXIT_FAILED, EXIT_INCOMPLETE, EXIT_OK, run_pipeline
from workflows.run_dir import read_json
from workflows.stage_registry import StageIncompleteError, not_implemented
from workflows.stage_runner import PipelineConfigError

Compose = Callable[..., DictConfig]


def _statuses(summary: dict[str, Any]) -> dict[str, str]:
    """Stage -> status of a summary."""
    return {row["stage"]: row["status"] for row in summary["stages"]}


@pytest.fixture
def run(compose: Compose, tmp_path: Path) -> Callable[..., dict[str, Any]]:
    """Return ``run(*overrides, registry=toy)``: one pipeline invocation in ``tmp_path/run``."""
    CALLS.clear()

    def _run(*overrides: str, registry: Any = None, run_dir: Path | None = None) -> dict[str, Any]:
        cfg = compose("+exp=gm_loco", "+scale=smoke", f"run_dir={run_dir or tmp_path / 'run'}", *overrides)
        return run_pipeline(cfg, registry=registry or toy_registry())

    return _run


def test_first_run_records_everything(run: Callable[..., dict[str, Any]], tmp_path: Path) -> None:
    """Toy stages are done with outputs and metrics; the stubbed later stages are reported as not implemented."""
    summary = run()
    assert summary["exit_code"] == EXIT_OK
    statuses = _statuses(summary)
    assert statuses["train_teacher"] == statuses["distill"] == "done"
    for name in ("export", "eval_mpm", "analyze_logs", "mismatch"):
        assert statuses[name] == "not_implemented"
    root = tmp_path / "run"
    for rel in (
        "config.yaml",
        "manifest.json",
        "summary.json",
        "train_teacher/checkpoint.json",
        "distill/student.json",
    ):
        assert (root / rel).is_file(), rel
    assert list((root / "git").glob("gmloco-*.diff")) and list((root / "tb").iterdir())
    metrics = read_json(root / "distill" / "metrics.json")
    assert metrics["metrics"] == {"action_loss": 0.25}
    manifest = read_json(root / "manifest.json")
    assert manifest["stages"]["distill"]["outputs"].keys() == {"metrics.json", "student.json"}
    assert manifest["stages"]["export"]["message"] == "not implemented yet (issue 6)"
    assert manifest["invocations"][0]["seed"] == 42 and manifest["invocations"][0]["scale"] == "smoke"
    assert read_json(root / "summary.json") == summary


def test_rerun_skips_done_stages(run: Callable[..., dict[str, Any]]) -> None:
    """A second identical invocation runs nothing that is already done; volatile keys do not matter."""
    run()
    summary = run("max_minutes=30", "tracking.tensorboard=false")
    assert _statuses(summary)["train_teacher"] == _statuses(summary)["distill"] == "skipped"
    assert CALLS == {"train_teacher": 1, "distill": 1}


def test_force_reruns_only_the_named_stage(run: Callable[..., dict[str, Any]]) -> None:
    """``force=[distill]`` reruns distill only; ``force=true`` reruns both."""
    run()
    assert _statuses(run("force=[distill]"))["distill"] == "done"
    assert CALLS == {"train_teacher": 1, "distill": 2}
    run("force=true")
    assert CALLS == {"train_teacher": 2, "distill": 3}


def test_config_change_invalidates_the_stage_and_downstream(run: Callable[..., dict[str, Any]], tmp_path: Path) -> None:
    """A changed stage reruns only when force names it (or a stage it needs); its old results are kept otherwise.

    Hashes chain through ``needs``: forcing the teacher with a changed setting reruns the distillation too.
    """
    run()
    student = tmp_path / "run" / "distill" / "student.json"
    before = student.read_bytes()
    with pytest.raises(PipelineConfigError, match=r"force=\[distill\]") as info:
        run("distill.max_iterations=3")
    assert info.value.key == "force" and student.read_bytes() == before
    s = _statuses(run("distill.max_iterations=3", "force=[distill]"))
    assert (s["train_teacher"], s["distill"]) == ("skipped", "done")
    with pytest.raises(PipelineConfigError, match="train_teacher"):
        run("distill.max_iterations=3", "train_teacher.num_envs=8")
    s = _statuses(run("distill.max_iterations=3", "train_teacher.num_envs=8", "force=[train_teacher]"))
    assert (s["train_teacher"], s["distill"]) == ("done", "done")
    s = _statuses(run("distill.max_iterations=3", "train_teacher.num_envs=8", "seed=7", "force=true"))
    assert (s["train_teacher"], s["distill"]) == ("done", "done")


def test_run_dir_refuses_another_experiment(
    run: Callable[..., dict[str, Any]], compose: Callable[..., DictConfig], tmp_path: Path
) -> None:
    """A gm_loco run directory records its experiment; +exp=ppo_rft3d in it is refused before anything is written."""
    run()
    root = tmp_path / "run"
    assert read_json(root / "manifest.json")["exp_name"] == "gm_loco"
    checkpoint = (root / "train_teacher" / "checkpoint.json").read_bytes()
    cfg = compose("+exp=ppo_rft3d", f"run_dir={root}", "+scale=smoke")
    with pytest.raises(PipelineConfigError, match="holds a 'gm_loco' run") as info:
        run_pipeline(cfg, toy_registry())
    assert info.value.key == "run_dir"
    assert (root / "train_teacher" / "checkpoint.json").read_bytes() == checkpoint


def test_missing_output_reruns_the_stage(run: Callable[..., dict[str, Any]], tmp_path: Path) -> None:
    """A stage whose recorded output was deleted is not trusted and runs again."""
    run()
    (tmp_path / "run" / "train_teacher" / "checkpoint.json").unlink()
    s = _statuses(run())
    assert (s["train_teacher"], s["distill"]) == ("done", "skipped")


def test_moved_run_directory_still_resumes(run: Callable[..., dict[str, Any]], tmp_path: Path) -> None:
    """Hashes do not contain the run directory, so a copied run (e.g. back from the GPU machine) resumes."""
    run()
    shutil.copytree(tmp_path / "run", tmp_path / "moved")
    s = _statuses(run(run_dir=tmp_path / "moved"))
    assert (s["train_teacher"], s["distill"]) == ("skipped", "skipped")


def test_crash_is_recorded_and_resume_keeps_finished_work(run: Callable[..., dict[str, Any]], tmp_path: Path) -> None:
    """A stage that raises is ``failed`` (exit 1, traceback saved); the rerun skips the finished teacher."""

    def crashing_student(cfg: Any) -> dict[str, float]:
        raise RuntimeError("injected crash")

    summary = run(registry=toy_registry(student=crashing_student))
    assert summary["exit_code"] == EXIT_FAILED
    assert _statuses(summary)["distill"] == "failed"
    assert "injected crash" in (tmp_path / "run" / "distill" / "error.log").read_text()
    s = _statuses(run())
    assert (s["train_teacher"], s["distill"]) == ("skipped", "done")
    assert CALLS["train_teacher"] == 1
    assert not (tmp_path / "run" / "distill" / "error.log").exists()


def test_unimplemented_upstream_blocks_a_real_stage(run: Callable[..., dict[str, Any]]) -> None:
    """An implemented stage whose input stage is not implemented is ``blocked`` and never called."""
    summary = run(registry=toy_registry(teacher=not_implemented("train_teacher")))
    s = _statuses(summary)
    assert s["train_teacher"] == "not_implemented"
    assert s["distill"] == "blocked"
    assert "train_teacher (not_implemented)" in summary["stages"][1]["message"]
    assert CALLS["distill"] == 0 and summary["exit_code"] == EXIT_OK


def test_time_boxes(run: Callable[..., dict[str, Any]]) -> None:
    """A stage that stops at its time box is ``incomplete`` (exit 3); a used-up pipeline box defers stages."""

    def timeboxed_student(cfg: Any) -> dict[str, float]:
        raise StageIncompleteError("stopped at 9.0 min after iteration 12")

    summary = run("max_minutes=9", registry=toy_registry(student=timeboxed_student))
    assert summary["exit_code"] == EXIT_INCOMPLETE
    assert _statuses(summary)["distill"] == "incomplete"
    assert 0 < summary["stages"][0]["metrics"]["max_minutes"] <= 9  # the stage saw its capped time box
    summary = run("max_minutes=1e-12", "force=true")  # used up before the first stage starts
    assert _statuses(summary)["train_teacher"] == "deferred" and summary["exit_code"] == EXIT_INCOMPLETE


def test_stage_selection(run: Callable[..., dict[str, Any]]) -> None:
    """Stages outside ``stages`` are ``disabled``; a later run of distill alone uses the recorded teacher."""
    s = _statuses(run("stages=[train_teacher]"))
    assert s["train_teacher"] == "done" and s["distill"] == "disabled"
    s = _statuses(run("stages=[distill]"))
    assert (s["train_teacher"], s["distill"]) == ("disabled", "done")


def test_stage_is_told_whether_to_resume(run: Callable[..., dict[str, Any]]) -> None:
    """``<stage>.resume``: true on a first run and after an incomplete one; false when forced.

    Another config needs ``force`` once the stage's folder holds results.
    """
    seen: list[bool] = []
    stop = [True]

    def teacher(cfg: Any) -> dict[str, float]:
        seen.append(bool(cfg.train_teacher.resume))
        if stop[0]:
            raise StageIncompleteError("time box")
        return toy_teacher(cfg)

    registry = toy_registry(teacher=teacher)
    run(registry=registry)  # first attempt stops at its time box
    stop[0] = False
    run(registry=registry)  # same config: continue
    run("force=[train_teacher]", registry=registry)  # forced: start fresh
    run("train_teacher.num_envs=8", "force=[train_teacher]", registry=registry)  # another config: start fresh
    assert seen == [True, True, False, False]
