# SPDX-License-Identifier: Apache-2.0
"""The MPM evaluation's command line: the coupling frame must divide the policy step."""

from __future__ import annotations

from pathlib import Path

import pytest

from gmloco.eval.g1.cli import _parse


def test_frame_dt_and_substeps_reach_the_parsed_arguments() -> None:
    """A 5 ms frame with one rigid step (the setting the G1 probes walk longest on) is accepted."""
    a = _parse(["--out", "x", "--frame-dt", "0.005", "--substeps", "1"])
    assert a.frame_dt == 0.005 and a.substeps == 1


@pytest.mark.parametrize(
    "argv", [["--frame-dt", "0.003"], ["--frame-dt", "0.04"], ["--substeps", "0"], ["--tolerance", "0"]]
)
def test_a_frame_that_does_not_divide_the_policy_step_is_refused(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    """3 ms and 40 ms frames do not fit 50 Hz policy steps, 0 substeps no physics: a usage error naming the value."""
    with pytest.raises(SystemExit):
        _parse(["--out", "x", *argv])
    assert argv[1] in capsys.readouterr().err


def test_window_and_solver_flags_reach_the_evaluation_config(monkeypatch: pytest.MonkeyPatch) -> None:
    """--window-lead, --particles-per-voxel and --rheology-solver end up in the G1EvalCfg that run() gets."""
    import gmloco.eval.g1.cli as cli

    seen = {}

    def fake_run(cfg):  # noqa: ANN001, ANN202
        seen["cfg"] = cfg
        return {}, True

    monkeypatch.setattr(cli, "run", fake_run)
    cli.main(["--out", "x", "--window-width", "0.6", "--window-lead", "0.0", "--particles-per-voxel", "1",
              "--rheology-solver", "cr,gs", "--iters", "500", "--tolerance", "2e-4"])  # fmt: skip
    cfg = seen["cfg"]
    assert (cfg.window.width, cfg.window.lead, cfg.window.particles_per_voxel) == (0.6, 0.0, 1)
    assert (cfg.solver.rheology_solver, cfg.solver.max_iterations, cfg.solver.tolerance) == ("cr,gs", 500, 2e-4)


def test_zero_particles_per_voxel_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    """A window without particles would be an evaluation without sand: a usage error."""
    with pytest.raises(SystemExit):
        _parse(["--out", "x", "--particles-per-voxel", "0"])
    assert "--particles-per-voxel 0" in capsys.readouterr().err


@pytest.mark.parametrize(("name", "arg"), [("auto", "auto"), ("gs", "gs"), ("cr,gs", ("cr", "gs")),
                                           (" cg , jacobi , gs ", ("cg", "jacobi", "gs"))])  # fmt: skip
def test_rheology_solver_names_become_newton_solver_arguments(name: str, arg: object) -> None:
    """One name stays a string; a comma-separated warm-start sequence becomes Newton's tuple."""
    from gmloco.eval.mpm.coupled_setup import rheology_solver_arg

    assert rheology_solver_arg(name) == arg


def test_an_empty_rheology_solver_is_refused() -> None:
    """No solver named: a ValueError that says what to write."""
    from gmloco.eval.mpm.coupled_setup import rheology_solver_arg

    with pytest.raises(ValueError, match="name a solver"):
        rheology_solver_arg(" , ")


def test_cell_capacity_factor_below_one_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    """A capacity under the windows' initial cells overflows at once: 0.5 is a usage error, 1.5 parses."""
    with pytest.raises(SystemExit):
        _parse(["--out", "x", "--cell-capacity-factor", "0.5"])
    assert "--cell-capacity-factor 0.5" in capsys.readouterr().err
    assert _parse(["--out", "x", "--cell-capacity-factor", "1.5"]).cell_capacity_factor == 1.5


def test_window_defaults_are_the_evaluation_defaults() -> None:
    """Without window flags the command line scores at ``G1EvalCfg``'s window (size and lead) and bed."""
    from gmloco.eval.g1.config import G1EvalCfg

    a, base = _parse(["--out", "x"]), G1EvalCfg()
    assert (a.window_length, a.window_width, a.window_lead) == (base.window.length, base.window.width, base.window.lead)
    assert a.bed_depth == base.bed_depth


def test_shard_reaches_the_config_and_bad_shards_are_refused(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """--shard 1/4 scores a quarter of each cell: with four speeds, the 25 episodes at 1.5 m/s."""
    import gmloco.eval.g1.cli as cli
    from gmloco.eval.g1.config import episode_specs

    seen = {}

    def fake_run(cfg):  # noqa: ANN001, ANN202
        seen["cfg"] = cfg
        return {}, True

    monkeypatch.setattr(cli, "run", fake_run)
    cli.main(["--out", "x", "--shard", "1/4"])
    specs = episode_specs(seen["cfg"])
    assert len(specs) == 25 and {s.speed for s in specs} == {1.5} and specs[0].index == 1
    for bad in ("4/4", "1-4", "x/2"):
        with pytest.raises(SystemExit):
            _parse(["--out", "x", "--shard", bad])
        assert "--shard" in capsys.readouterr().err


def test_cli_args_give_back_the_config() -> None:
    """A config with every command-line field off its default survives cli_args -> parse -> cfg_from_args."""
    from dataclasses import replace

    from gmloco.eval.g1.cli import cfg_from_args, cli_args
    from gmloco.eval.g1.config import G1EvalCfg
    from gmloco.eval.mpm.window import SandWindowCfg

    base = G1EvalCfg()
    cfg = replace(base, policy_path="a/p.onnx", out_dir="o", terrains=("basalt", "transition"),
                  scenarios=("straight", "circle"), speeds=(1.25, 2.0), num_episodes=7, episode_s=5.0,
                  circle_radius=1.5, course_slack=0.1, bed_depth=0.25,
                  window=SandWindowCfg(moving=False, length=1.1, width=0.7, lead=-0.05, particles_per_voxel=1),
                  robots_per_batch=9, refill=False, retire_idle_lanes=False, cell_capacity_factor=1.25,
                  solver=replace(base.solver, voxel_size=0.04, max_iterations=321, tolerance=1e-6, frame_dt=0.01,
                                 rigid_substeps=2, rheology_solver="jacobi,gs"),
                  record_mcap=False, resume=False, fit_time_box=False, seed=3)  # fmt: skip
    back = cfg_from_args(_parse([*cli_args(cfg), "--out", "o"]))
    assert back == cfg
    per_cell = cli_args(cfg, cells=False)
    assert "--terrains" not in per_cell and "--scenarios" not in per_cell and "--out" not in per_cell
    with pytest.raises(ValueError, match="lane_gap"):
        cli_args(replace(cfg, lane_gap=3.0))


@pytest.mark.parametrize(
    ("content", "words"), [(None, "does not exist"), (b"", "no graph"), (b"\xff\x00junk", "not an ONNX model")]
)
def test_a_missing_or_non_onnx_policy_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: bytes | None, words: str
) -> None:
    """``--policy`` on a missing, empty or non-ONNX file: one error line, exit code 2, no traceback, no run."""
    import gmloco.eval.g1.cli as cli

    policy = tmp_path / "policy.onnx"
    if content is not None:
        policy.write_bytes(content)
    with pytest.raises(SystemExit) as info:
        cli.main(["--out", str(tmp_path / "out"), "--policy", str(policy)])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert words in err and str(policy) in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("argv", [["--num-episodes", "-1"], ["--episode-s", "0"], ["--speeds", "1.0", "-2"]])
def test_non_positive_counts_and_durations_are_refused(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """A negative episode count, a zero episode length or a negative speed is a usage error naming the value."""
    with pytest.raises(SystemExit) as info:
        _parse(["--out", "x", *argv])
    assert info.value.code == 2 and argv[-1] in capsys.readouterr().err


def test_resuming_a_folder_at_another_window_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A folder walked on the grid's axes (no ``turn_with_robot`` recorded) is not resumed at a turning window."""
    import json

    import gmloco.eval.g1.cli as cli
    from gmloco.eval.g1.cli import cfg_from_args
    from gmloco.eval.g1.run import resume_problem

    policy = Path(__file__).resolve().parents[4] / "artifacts" / "ppo_rft3d" / "policy.onnx"
    if not policy.exists():
        pytest.skip(f"no exported policy at {policy}")
    out = tmp_path / "run"
    out.mkdir()
    (out / "episodes.jsonl").write_text("")
    window = {"moving": True, "length": 1.4, "width": 0.6, "lead": 0.2, "offset_y": 0.0, "particles_per_voxel": 2,
              "jitter": 0.5}  # fmt: skip
    (out / "summary.json").write_text(json.dumps({"cfg": {"window": window}}))
    with pytest.raises(SystemExit) as info:
        cli.main(["--out", str(out), "--policy", str(policy)])
    err = capsys.readouterr().err
    assert info.value.code == 2 and "turn_with_robot False -> True" in err and "--window-fixed-axes" in err
    assert resume_problem(cfg_from_args(_parse(["--out", str(out), "--window-fixed-axes"]))) is None
    assert resume_problem(cfg_from_args(_parse(["--out", str(out), "--fresh"]))) is None  # a fresh start mixes nothing
