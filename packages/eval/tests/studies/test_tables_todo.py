# SPDX-License-Identifier: Apache-2.0
"""What the tables still need as a queue task file: resumes of cut runs, reruns of rows that left their window."""

from __future__ import annotations

import json
from dataclasses import asdict, replace
from pathlib import Path

import pytest

from gmloco.eval.g1.cli import _parse, cfg_from_args
from gmloco.eval.g1.config import G1EvalCfg, episode_specs
from gmloco.eval.g1.queue import check_tasks, file_tasks
from gmloco.eval.mpm.window import SandWindowCfg
from gmloco.eval.studies.tables_todo import cfg_from_summary, main, todo


def _run(d: Path, cfg: G1EvalCfg, done: int, **row: object) -> Path:
    """A run folder: summary.json with ``cfg`` and ``done`` of its episodes, each row updated with ``row``."""
    d.mkdir(parents=True)
    (d / "summary.json").write_text(json.dumps({"complete": False, "cfg": asdict(cfg)}))
    rows = [{"key": s.key, "terrain": s.terrain, "scenario": s.scenario, "speed": s.speed, "success": False,
             "alive_s": 3.0, "window_exit_early": False, "sole_behind_m": 0.4, "sole_ahead_m": 0.1,
             "sole_side_m": 0.2} | row for s in episode_specs(cfg)[:done]]  # fmt: skip
    (d / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    return d


def test_a_summary_cfg_gives_back_the_run_config() -> None:
    """A cfg through asdict, JSON and cfg_from_summary comes back equal (tuples, window / solver / failure)."""
    cfg = replace(G1EvalCfg(), terrains=("basalt",), shards=4, shard=2, window=SandWindowCfg(length=1.4, width=1.4))
    assert cfg_from_summary(json.loads(json.dumps(asdict(cfg)))) == cfg
    assert cfg_from_summary(asdict(cfg) | {"an_old_key": 1}) == cfg  # older runs' extra keys are ignored


def test_cut_shares_are_resumed_and_window_exits_rerun(tmp_path: Path) -> None:
    """Cut shares are resumed under their own names, rows that left their window rerun at a covering one.

    Row A: share 1 of 4 cut at 20 of 25 -> one resume with --shard 1/4. Row B: 40 % turn exits at the tables'
    window -> four shares at a square window. Every line parses as g1_eval_cli will.
    """
    fixed_axes = replace(G1EvalCfg().window, turn_with_robot=False)  # a turning window keeps its shape instead
    base = replace(G1EvalCfg(), policy_path="p.onnx", shards=4, window=fixed_axes)
    a = [_run(tmp_path / f"a_share{i}of4", replace(base, shard=i), 25 if i != 1 else 20) for i in range(4)]
    b = _run(tmp_path / "b", replace(base, terrains=("basalt",), shards=1), 100)
    rows = [json.loads(x) for x in (b / "episodes.jsonl").read_text().splitlines()]
    for r in rows[:40]:
        r.update(window_exit_early=True, window_exit_cause="turn")
    (b / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    tasks = todo([("td", d) for d in a] + [("td", b)])
    resume, *reruns = tasks
    assert resume.name == "a_share1of4" and resume.resume_from == str(a[1]) and "--shard 1/4" in resume.line
    assert "95 of 100" in resume.why and "5 left" in resume.why
    assert len(reruns) == 4 and all(t.resume_from is None for t in reruns)
    cfg = cfg_from_args(_parse([*reruns[2].line.split()[1:], "--out", "x"]))
    assert cfg.terrains == ("basalt",) and cfg.window.length == cfg.window.width == pytest.approx(1.4)
    assert (
        cfg.num_episodes == 100
        and "--shard 2/4" in reruns[2].line
        and "40 % early window exits (turn)" in reruns[2].why
    )
    out = tmp_path / "todo.txt"
    main(["--run", f"td={a[1]}", "--run", f"td={b}", "--out", str(out), "--episodes", "25"])
    check_tasks(file_tasks(out, []))
    assert todo([("td", a[0])], episodes=25) == []  # a complete row without exits needs nothing


def test_bad_run_arguments_stop_with_the_expected_form(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--run`` without ``LABEL=`` and a folder without summary.json: exit 2 saying what to pass."""
    with pytest.raises(SystemExit):
        main(["--run", str(tmp_path), "--out", str(tmp_path / "t.txt")])
    assert "expected LABEL=RUN_DIR" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--run", f"td={tmp_path}", "--out", str(tmp_path / "t.txt")])
    assert "no summary.json" in capsys.readouterr().err


def test_rows_whose_exits_came_with_the_fall_are_not_rerun(tmp_path: Path) -> None:
    """Exits that came with the fall do not call for a rerun; ``fall_exits`` counts them.

    40 % reach exits 0.3 s before a tilt, 5 % 2 s before: noted, not rerun (5 % is at the tables' threshold); with
    ``fall_exits`` all 45 % count and the row is rerun.
    """
    cfg = replace(G1EvalCfg(), policy_path="p.onnx", terrains=("poppy_seed",))
    d = _run(tmp_path / "c", cfg, 100, reason="tilt")
    rows = [json.loads(x) for x in (d / "episodes.jsonl").read_text().splitlines()]
    for k, r in enumerate(rows[:45]):
        r.update(window_exit_early=True, window_exit_cause="reach", window_exit_s=2.7 if k < 40 else 1.0)
    (d / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    notes: list[str] = []
    assert todo([("td", d)], notes=notes) == []
    assert len(notes) == 1 and "40 of its 45 early window exits came within 0.75 s before the fall" in notes[0]
    reruns = todo([("td", d)], fall_exits=True)
    assert len(reruns) == 4 and "45 % early window exits (reach)" in reruns[0].why


def test_a_window_recorded_before_it_turned_reads_as_fixed_axes() -> None:
    """A summary's window without ``turn_with_robot`` (older runs) kept the grid's axes; a recorded one is kept."""
    from gmloco.eval.studies.tables_todo import cfg_from_summary

    old = cfg_from_summary({"window": {"moving": True, "length": 1.4, "width": 1.4, "lead": 0.2}})
    assert not old.window.turn_with_robot and old.window.length == 1.4
    new = cfg_from_summary({"window": {"moving": True, "turn_with_robot": True, "turn_step": 0.05}})
    assert new.window.turn_with_robot and new.window.turn_step == 0.05
