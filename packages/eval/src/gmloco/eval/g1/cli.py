# SPDX-License-Identifier: Apache-2.0
"""Command line of the MPM evaluation without Hydra (the GPU machine): ``python -m gmloco.eval.g1.cli``.

    python -m gmloco.eval.g1.cli --out results/mpm_eval/ppo_rft3d --terrains dry_sand --num-episodes 100
        --robots-per-batch 32 --max-minutes 8.5

Time-boxed and resumable (rerun with the same ``--out``); prints the summary metrics as JSON.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace

from gmloco.eval.g1.config import G1EvalCfg
from gmloco.eval.g1.policy import policy_problem
from gmloco.eval.g1.run import resume_problem, run
from gmloco.eval.mpm.box_scene import frame_dt_problem
from gmloco.eval.mpm.window import SandWindowCfg

__all__ = ["cfg_from_args", "cli_args", "main"]

_SOLVER = G1EvalCfg().solver
"""The evaluation's default MPM numerics (the command line's defaults)."""
_WINDOW = G1EvalCfg().window
"""The evaluation's default sand window."""


def _parse(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True)
    p.add_argument("--policy", default=G1EvalCfg.policy_path)
    p.add_argument("--terrains", nargs="+", default=["dry_sand"])
    p.add_argument("--scenarios", nargs="+", default=["straight"], choices=["straight", "circle"])
    p.add_argument("--speeds", type=float, nargs="+", default=[1.0, 1.5, 2.0, 2.5])
    p.add_argument("--num-episodes", type=int, default=100)
    p.add_argument(
        "--shard",
        default="0/1",
        help="I/N: score the share I (0 .. N-1) of each cell's episodes, those with index k %% N == I "
        "(several GPUs split one row; paper_tables pools the folders)",
    )
    p.add_argument("--episode-s", type=float, default=G1EvalCfg.episode_s, help="episode = course time limit [s]")
    p.add_argument("--circle-radius", type=float, default=G1EvalCfg.circle_radius, help="circular walk radius [m]")
    p.add_argument(
        "--course-slack",
        type=float,
        default=G1EvalCfg.course_slack,
        help="fraction of the commanded path that may be left at the time limit and still count as finished",
    )
    p.add_argument("--voxel", type=float, default=_SOLVER.voxel_size, help="MPM voxel size [m]")
    p.add_argument("--iters", type=int, default=_SOLVER.max_iterations, help="rheology iterations")
    p.add_argument(
        "--frame-dt",
        type=float,
        default=_SOLVER.frame_dt,
        help="MPM frame = coupling period [s]; must divide the 0.02 s policy step (0.01, 0.005, 0.0025)",
    )
    p.add_argument(
        "--tolerance", type=float, default=_SOLVER.tolerance, help="rheology residual at which a frame's solve stops"
    )
    p.add_argument(
        "--rheology-solver",
        default=_SOLVER.rheology_solver,
        help="SolverImplicitMPM rheology solver: auto, gs, jacobi, or a warm-start sequence such as cr,gs",
    )
    p.add_argument("--substeps", type=int, default=_SOLVER.rigid_substeps, help="rigid steps per frame")
    p.add_argument("--bed-depth", type=float, default=G1EvalCfg.bed_depth, help="sand depth of flat / rough beds [m]")
    p.add_argument("--robots-per-batch", type=int, default=G1EvalCfg.robots_per_batch)
    p.add_argument(
        "--no-refill", action="store_true", help="one solver per batch of robots, lanes idle after their episode"
    )
    p.add_argument(
        "--keep-idle-lanes",
        action="store_true",
        help="keep a lane's sand in the MPM solve after its robot's last episode (the runs up to the ablation-circle runs)",
    )
    p.add_argument("--static-bed", action="store_true", help="naive baseline: a bed covering the course")
    p.add_argument("--window-length", type=float, default=_WINDOW.length)
    p.add_argument("--window-width", type=float, default=_WINDOW.width)
    p.add_argument("--window-lead", type=float, default=_WINDOW.lead, help="window centre ahead of the pelvis [m]")
    p.add_argument(
        "--window-fixed-axes",
        action="store_true",
        help="keep the moving window's sides on the grid's axes (default: it turns with the robot's heading)",
    )
    p.add_argument(
        "--window-turn-step",
        type=float,
        default=_WINDOW.turn_step,
        help="heading change of the robot that turns the window to it [rad] (0.0524 = 3 degrees)",
    )
    p.add_argument(
        "--particles-per-voxel", type=int, default=SandWindowCfg.particles_per_voxel, help="particles per voxel edge"
    )
    p.add_argument(
        "--cell-capacity-factor",
        type=float,
        default=G1EvalCfg.cell_capacity_factor,
        help="active-cell capacity of the sparse grid as a multiple of the windows' initial cells",
    )
    p.add_argument("--no-mcap", action="store_true")
    p.add_argument("--max-minutes", type=float, default=None, help="time box of this call [min] (resumable)")
    p.add_argument(
        "--no-fit-time-box",
        action="store_true",
        help="with --max-minutes: run every cell as it comes until the time box drops its running episodes "
        "(default: a cell whose walks would not end in the time left is rebuilt with the lanes that fit)",
    )
    p.add_argument("--fresh", action="store_true", help="discard episodes.jsonl instead of resuming")
    p.add_argument("--device", default=None)
    p.add_argument("--seed", type=int, default=0)
    a = p.parse_args(argv)
    if (problem := frame_dt_problem(a.frame_dt)) is not None:
        p.error(f"--frame-dt: {problem}")
    try:
        a.shard, a.shards = (int(x) for x in a.shard.split("/"))
    except ValueError:
        p.error(f"--shard {a.shard!r}: write I/N, e.g. 2/4 for the third of four shares")
    if not 0 <= a.shard < a.shards:
        p.error(f"--shard {a.shard}/{a.shards}: the share I must be 0 .. N-1")
    if a.particles_per_voxel < 1:
        p.error(f"--particles-per-voxel {a.particles_per_voxel} must be >= 1")
    if not a.tolerance > 0.0:
        p.error(f"--tolerance {a.tolerance} must be > 0 (the rheology residual at which a frame's solve stops)")
    if a.cell_capacity_factor != 0 and a.cell_capacity_factor < 1.0:
        p.error(f"--cell-capacity-factor {a.cell_capacity_factor}: use >= 1 (or 0 for Newton's per-step allocation)")
    if a.substeps < 1:
        p.error(f"--substeps {a.substeps} must be >= 1 (rigid steps per MPM frame)")
    for flag, value in (("num-episodes", a.num_episodes), ("robots-per-batch", a.robots_per_batch)):
        if value < 1:
            p.error(f"--{flag} {value} must be >= 1")
    for flag, value in (("episode-s", a.episode_s), ("max-minutes", a.max_minutes), *(("speeds", v) for v in a.speeds)):
        if value is not None and not value > 0.0:
            p.error(f"--{flag} {value} must be > 0")
    return a


def cfg_from_args(a: argparse.Namespace) -> G1EvalCfg:
    """The evaluation config of parsed command-line arguments."""
    base = G1EvalCfg()
    return replace(
        base,
        policy_path=a.policy,
        out_dir=a.out,
        terrains=tuple(a.terrains),
        scenarios=tuple(a.scenarios),
        speeds=tuple(a.speeds),
        num_episodes=a.num_episodes,
        shard=a.shard,
        shards=a.shards,
        episode_s=a.episode_s,
        circle_radius=a.circle_radius,
        course_slack=a.course_slack,
        window=SandWindowCfg(
            moving=not a.static_bed,
            length=a.window_length,
            width=a.window_width,
            lead=a.window_lead,
            turn_with_robot=not a.window_fixed_axes,
            turn_step=a.window_turn_step,
            particles_per_voxel=a.particles_per_voxel,
        ),
        robots_per_batch=a.robots_per_batch,
        refill=not a.no_refill,
        retire_idle_lanes=not a.keep_idle_lanes,
        cell_capacity_factor=a.cell_capacity_factor,
        solver=replace(
            base.solver,
            voxel_size=a.voxel,
            max_iterations=a.iters,
            tolerance=a.tolerance,
            frame_dt=a.frame_dt,
            rigid_substeps=a.substeps,
            rheology_solver=a.rheology_solver,
        ),
        bed_depth=a.bed_depth,
        record_mcap=not a.no_mcap,
        max_minutes=a.max_minutes,
        fit_time_box=not a.no_fit_time_box,
        resume=not a.fresh,
        device=a.device,
        seed=a.seed,
    )


def cli_args(cfg: G1EvalCfg, cells: bool = True) -> list[str]:
    """The command-line arguments that give back ``cfg`` (the inverse of :func:`cfg_from_args`).

    Leaves out what a caller running several processes sets per process: ``--out``, ``--shard``, ``--max-minutes``
    and ``--device``; ``cells=False`` also leaves out ``--terrains`` and ``--scenarios`` (one task per cell).

    Raises:
        ValueError: ``cfg`` holds a setting the command line cannot express (e.g. other failure rules).
    """
    base = G1EvalCfg()
    if (cfg.bed_margin, cfg.lane_gap) != (base.bed_margin, base.lane_gap):
        raise ValueError(f"bed_margin {cfg.bed_margin} / lane_gap {cfg.lane_gap} differ from the defaults: the "
                         "command line cannot pass them")  # fmt: skip
    if cfg.failure != base.failure:
        raise ValueError(f"failure rules {cfg.failure} differ from the defaults: the command line cannot pass them")
    s, w = cfg.solver, cfg.window
    if replace(s, voxel_size=_SOLVER.voxel_size, max_iterations=_SOLVER.max_iterations, tolerance=_SOLVER.tolerance,
               frame_dt=_SOLVER.frame_dt, rigid_substeps=_SOLVER.rigid_substeps,
               rheology_solver=_SOLVER.rheology_solver) != _SOLVER:  # fmt: skip
        raise ValueError("the MPM solver config sets fields the command line cannot pass (only voxel, iterations, "
                         "tolerance, frame, rigid substeps and rheology solver)")  # fmt: skip
    if replace(w, moving=_WINDOW.moving, length=_WINDOW.length, width=_WINDOW.width, lead=_WINDOW.lead,
               turn_with_robot=_WINDOW.turn_with_robot, turn_step=_WINDOW.turn_step,
               particles_per_voxel=_WINDOW.particles_per_voxel) != _WINDOW:  # fmt: skip
        raise ValueError("the sand window sets fields the command line cannot pass (only moving, size, lead, "
                         "turning, turn step, particles per voxel)")  # fmt: skip
    out = ["--policy", cfg.policy_path]
    if cells:
        out += ["--terrains", *cfg.terrains, "--scenarios", *cfg.scenarios]
    out += ["--speeds", *(f"{v:g}" for v in cfg.speeds), "--num-episodes", str(cfg.num_episodes),
            "--episode-s", repr(cfg.episode_s), "--circle-radius", repr(cfg.circle_radius),
            "--course-slack", repr(cfg.course_slack), "--voxel", repr(s.voxel_size), "--iters", str(s.max_iterations),
            "--frame-dt", repr(s.frame_dt), "--tolerance", repr(s.tolerance), "--rheology-solver", s.rheology_solver,
            "--substeps", str(s.rigid_substeps), "--bed-depth", repr(cfg.bed_depth),
            "--robots-per-batch", str(cfg.robots_per_batch), "--window-length", repr(w.length),
            "--window-width", repr(w.width), "--window-lead", repr(w.lead),
            "--window-turn-step", repr(w.turn_step),
            "--particles-per-voxel", str(w.particles_per_voxel),
            "--cell-capacity-factor", repr(cfg.cell_capacity_factor), "--seed", str(cfg.seed)]  # fmt: skip
    flags = {"--no-refill": not cfg.refill, "--keep-idle-lanes": not cfg.retire_idle_lanes,
             "--static-bed": not w.moving, "--window-fixed-axes": not w.turn_with_robot, "--no-mcap": not cfg.record_mcap, "--fresh": not cfg.resume,
             "--no-fit-time-box": not cfg.fit_time_box}  # fmt: skip
    return out + [f for f, on in flags.items() if on]


def main(argv: list[str] | None = None) -> None:
    """Run the evaluation from command-line arguments; exit code 2 for bad arguments or a policy that is no ONNX."""
    a = _parse(argv)
    if (problem := policy_problem(a.policy)) is not None:  # checked before Warp and Newton start
        print(f"error: --policy {problem}. Nothing was run.", file=sys.stderr)
        raise SystemExit(2)
    cfg = cfg_from_args(a)
    if (problem := resume_problem(cfg)) is not None:
        print(f"error: {problem}. Nothing was run.", file=sys.stderr)
        raise SystemExit(2)
    metrics, complete = run(cfg)
    print(json.dumps({"complete": complete, **{k: v for k, v in metrics.items() if "/v" not in k}}, indent=1))


if __name__ == "__main__":
    main()
