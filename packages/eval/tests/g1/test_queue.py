# SPDX-License-Identifier: Apache-2.0
"""The several-GPU queue: every task runs once, one at a time per GPU, within the time box; failures are reported."""

from __future__ import annotations

import itertools
import subprocess
import sys
from pathlib import Path

import pytest

from gmloco.eval.g1.queue import Launch, QueueTask, cell_tasks, file_tasks, main, row_spans, run_queue


def _fake_launch(record: Path, fail: str = "") -> Launch:
    """A launcher that runs a short Python process instead of g1_eval_cli, logging (task, GPU, start, end)."""

    def launch(cmd: list[str], env: dict[str, str], log: Path) -> subprocess.Popen[bytes]:
        name = Path(cmd[cmd.index("--out") + 1]).name
        code = 3 if name == fail else 0
        script = ("import sys, time; t0 = time.time(); time.sleep(0.3); "
                  f"open({str(record)!r}, 'a').write(f'{name} {env['CUDA_VISIBLE_DEVICES']} {{t0}} {{time.time()}}\\n'); "
                  f"sys.exit({code})")  # fmt: skip
        return subprocess.Popen([sys.executable, "-c", script])

    return launch


def test_cells_become_tasks_and_queue_owned_flags_are_refused() -> None:
    """One task per (terrain, scenario) with the shared arguments; --out after -- is an error."""
    tasks = cell_tasks(["basalt", "dry_sand"], ["straight", "circle"], ["--policy", "p.onnx"])
    assert [t.name for t in tasks] == ["basalt__straight", "basalt__circle", "dry_sand__straight", "dry_sand__circle"]
    assert tasks[1].argv == ("--policy", "p.onnx", "--terrains", "basalt", "--scenarios", "circle")
    with pytest.raises(ValueError, match="--out is set by the queue"):
        cell_tasks(["basalt"], ["straight"], ["--out", "x"])


def test_every_task_runs_once_and_a_gpu_runs_one_at_a_time(tmp_path: Path) -> None:
    """Five tasks on two GPUs: all run, none twice, and no two overlap on one GPU."""
    record = tmp_path / "record.txt"
    tasks = [QueueTask(f"t{k}", ()) for k in range(5)]
    results = run_queue(tasks, ["0", "1"], tmp_path / "out", launch=_fake_launch(record), poll_s=0.05)
    assert [r.returncode for r in results] == [0] * 5 and {r.gpu for r in results} == {"0", "1"}
    lines = [line.split() for line in record.read_text().splitlines()]
    assert sorted(line[0] for line in lines) == [f"t{k}" for k in range(5)]
    for gpu in ("0", "1"):
        spans = sorted((float(a), float(b)) for _, g, a, b in lines if g == gpu)
        assert all(end <= nxt_start for (_, end), (nxt_start, _) in itertools.pairwise(spans))


def test_a_failed_task_is_reported_and_the_rest_go_on(tmp_path: Path) -> None:
    """Task t1 exits 3: its result says so, t0 and t2 still run."""
    tasks = [QueueTask(f"t{k}", ()) for k in range(3)]
    launch = _fake_launch(tmp_path / "record.txt", fail="t1")
    results = run_queue(tasks, ["0"], tmp_path / "out", launch=launch, poll_s=0.05)
    assert [r.returncode for r in results] == [0, 3, 0]


def test_nothing_starts_when_the_time_box_is_too_short(tmp_path: Path) -> None:
    """Half a minute left: no task is started (it would only build its solver); none has a GPU."""
    launch = _fake_launch(tmp_path / "record.txt")
    results = run_queue([QueueTask("t0", ())], ["0"], tmp_path / "out", max_minutes=0.5, launch=launch)
    assert results[0].gpu is None and results[0].returncode is None
    assert not (tmp_path / "record.txt").exists()


def test_command_line_refuses_a_gpu_named_twice(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--gpus 0 0 is a usage error that says how to name them."""
    with pytest.raises(SystemExit):
        main(["--gpus", "0", "0", "--out", str(tmp_path), "--terrains", "basalt", "--", "--policy", "p.onnx"])
    assert "name each GPU once" in capsys.readouterr().err


def test_shards_split_each_cell_into_shares() -> None:
    """--shards 4: four tasks per cell, cell after cell, each passing its --shard; --shard after -- is an error."""
    tasks = cell_tasks(["basalt", "poppy_seed"], ["straight"], ["--policy", "p.onnx"], shards=4)
    assert [t.name for t in tasks[:4]] == [f"basalt__straight__share{i}of4" for i in range(4)]
    assert tasks[4].name == "poppy_seed__straight__share0of4"
    assert tasks[2].argv[-2:] == ("--shard", "2/4")
    with pytest.raises(ValueError, match="--shard is set by the queue"):
        cell_tasks(["basalt"], ["straight"], ["--shard", "0/2"], shards=2)
    with pytest.raises(ValueError, match="at least 1"):
        cell_tasks(["basalt"], ["straight"], [], shards=0)


def test_a_task_file_gives_one_task_per_line(tmp_path: Path) -> None:
    """Names, quoted arguments and comments; the shared arguments after -- are appended; bad files say why."""
    f = tmp_path / "tasks.txt"
    f.write_text("# rows\nrow_a --policy a.onnx --terrains basalt --shard 0/4\n\n"
                 "row_b --policy 'my dir/b.onnx' --window-width 1.3  # wide\n")  # fmt: skip
    tasks = file_tasks(f, ["--no-mcap"])
    assert [t.name for t in tasks] == ["row_a", "row_b"]
    assert tasks[0].argv == ("--policy", "a.onnx", "--terrains", "basalt", "--shard", "0/4", "--no-mcap")
    assert tasks[1].argv == ("--policy", "my dir/b.onnx", "--window-width", "1.3", "--no-mcap")
    for text, why in (("a --out x\n", "--out is set by the queue"), ("a\na\n", "used twice"),
                      ("../a --policy p\n", "must be a folder name"), ("# nothing\n", "no task in it")):  # fmt: skip
        f.write_text(text)
        with pytest.raises(ValueError, match=why):
            file_tasks(f, [])
    with pytest.raises(ValueError, match="no such file"):
        file_tasks(tmp_path / "missing.txt", [])


def test_the_command_line_runs_a_task_file_and_names_each_policy(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """--tasks runs every line; the printed combine command labels each run by its own policy's folder."""
    import gmloco.eval.g1.queue as q

    record = tmp_path / "record.txt"
    real = q.run_queue
    monkeypatch.setattr(q, "run_queue", lambda tasks, gpus, out, minutes: real(tasks, gpus, out, minutes,
                                                                                launch=_fake_launch(record),
                                                                                poll_s=0.05))  # fmt: skip
    f = tmp_path / "tasks.txt"
    f.write_text("r1 --policy artifacts/td/policy.onnx\nr2 --policy artifacts/rigid/policy.onnx\n")
    results = main(["--gpus", "0", "1", "--out", str(tmp_path / "out"), "--tasks", str(f)])
    assert [r.returncode for r in results] == [0, 0]
    out = capsys.readouterr().out
    assert f"--run td={tmp_path / 'out' / 'r1'}" in out and f"--run rigid={tmp_path / 'out' / 'r2'}" in out
    for extra in (["--terrains", "basalt"], ["--shards", "2"]):
        with pytest.raises(SystemExit):
            main(["--gpus", "0", "--out", str(tmp_path / "out"), "--tasks", str(f), *extra])
        assert "--terrains" in capsys.readouterr().err


def test_a_row_in_shares_gets_its_wall_clock(tmp_path: Path) -> None:
    """Four shares of one row on two GPUs: the row spans the first start to the last end; an unfinished row is left out."""
    tasks = [QueueTask(f"row_share{i}of4", ()) for i in range(4)] + [QueueTask("cell__share0of2", ())]
    results = run_queue(tasks, ["0", "1"], tmp_path / "out", launch=_fake_launch(tmp_path / "r.txt"), poll_s=0.05)
    assert all(r.started_min is not None for r in results)
    rows = row_spans(results)
    assert list(rows) == ["row"]  # cell__share1of2 was never a task: that row is not whole
    span = rows["row"]
    assert span["shares"] == 4 and span["gpus"] == ["0", "1"] and span["returncodes"] == [0] * 4
    ends = [(r.started_min or 0.0) + r.minutes for r in results[:4]]
    assert span["wall_minutes"] == pytest.approx(max(ends) - min(r.started_min or 0.0 for r in results[:4]), abs=0.011)
    assert span["wall_minutes"] >= max(r.minutes for r in results[:4])


def test_check_parses_every_task_without_a_gpu(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--check: good lines parse and nothing runs; a line g1_eval_cli refuses is named with the reason."""
    f = tmp_path / "tasks.txt"
    f.write_text("a --policy p.onnx --terrains basalt --shard 1/4\nb --scenarios circle --speeds 1.0 2.0\n")
    assert main(["--tasks", str(f), "--check"]) == []
    assert "2 tasks parse: a, b" in capsys.readouterr().out
    assert not (tmp_path / "a").exists()
    f.write_text("a --policy p.onnx\nbad --scenarios zigzag\n")
    with pytest.raises(SystemExit):
        main(["--tasks", str(f), "--check"])
    err = capsys.readouterr().err
    assert "task bad" in err and "zigzag" in err
    with pytest.raises(SystemExit):
        main(["--tasks", str(f)])  # to run, --gpus and --out are needed
    assert "--gpus and --out are required" in capsys.readouterr().err
