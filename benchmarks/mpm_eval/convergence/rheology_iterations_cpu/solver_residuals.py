# SPDX-License-Identifier: Apache-2.0
"""How far the rheology solve gets per frame while the G1 walks on MPM sand, per Newton rheology solver (issue 9).

    python benchmarks/mpm_eval/convergence/rheology_iterations_cpu/solver_residuals.py --solvers gs cr,gs --frames 120 --iters 1000
        --out results/mpm_eval/convergence/rheology_iterations_cpu/residuals.jsonl

One robot (the td student, 1.0 m/s) on the evaluation's moving window (1.8 x 0.6 m, 30 cm of dry sand), 5 ms
frames, one rigid substep, on the CPU, where Newton runs its eager solver loop and reports the residual every
solve_granularity sweeps (25 for Gauss-Seidel) when verbose. Each frame's trace (iteration, l2 and linf residual
relative to the tolerance scale) is appended as one JSON line per (solver, frame), with the frame's wall time and
the robot's pelvis height. The frames differ between solvers after the first (each solver walks its own sand).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import re
import time
from pathlib import Path

GS_LINE = re.compile(r"iteration #(\d+)\s+res\(l2\)=([0-9.eE+-]+|nan|inf), res\(linf\)=([0-9.eE+-]+|nan|inf)")
LIN_LINE = re.compile(r"(\w+) terminated after (\d+) iterations with residual ([0-9.eE+-]+|nan|inf)")


def parse(text: str) -> dict:
    """Gauss-Seidel trace [(iteration, l2, linf)] and the Krylov warm start's (name, iterations, residual)."""
    trace = [(int(m[1]), float(m[2]), float(m[3])) for m in GS_LINE.finditer(text)]
    lin = [(m[1], int(m[2]), float(m[3])) for m in LIN_LINE.finditer(text)]
    return {"trace": trace, "linear": lin}


def run(solver: str, args: argparse.Namespace) -> None:
    """Walk ``args.frames`` frames with one rheology solver; append one line per frame to ``args.out``."""
    from gmloco.eval.g1.policy import load_policy
    from gmloco.eval.g1.scene import G1MpmScene
    from gmloco.eval.g1.scene_cfg import G1MpmSceneCfg
    from gmloco.eval.mpm.box_scene import MpmSolverCfg
    from gmloco.eval.mpm.window import SandWindowCfg
    from gmloco.eval.mpm.window_terrain import terrain_cfg

    cfg = G1MpmSceneCfg(
        terrain=terrain_cfg("dry_sand", depth=0.3),
        window=SandWindowCfg(moving=True, length=1.8, width=0.6, lead=0.2),
        solver=MpmSolverCfg(
            voxel_size=args.voxel,
            frame_dt=0.005,
            rigid_substeps=1,
            max_iterations=args.iters,
            tolerance=args.tol,
            rheology_solver=solver,
        ),
        commands=((1.0, 0.0, 0.0),),
        device="cpu",
    )
    scene = G1MpmScene(cfg, load_policy(args.policy, 1))
    scene.mpm.verbose = True
    with Path(args.out).open("a") as f:
        for frame in range(args.frames):
            buf = io.StringIO()
            t0 = time.perf_counter()
            with contextlib.redirect_stdout(buf):
                scene.step()
            row = {"solver": solver, "frame": frame, "wall_s": time.perf_counter() - t0, "iters_max": args.iters,
                   "tol": args.tol, "voxel": args.voxel, "pelvis_z": float(scene.base_q[-1][0][2]),
                   **parse(buf.getvalue())}  # fmt: skip
            f.write(json.dumps(row) + "\n")
            f.flush()
            last = row["trace"][-1] if row["trace"] else None
            print(f"{solver} frame {frame}: {last} lin {row['linear']} {row['wall_s']:.1f}s", flush=True)


def main() -> None:
    """Parse the command line and run every solver in turn."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--solvers", nargs="+", default=["gs", "cr,gs"])
    p.add_argument("--frames", type=int, default=120)
    p.add_argument("--iters", type=int, default=1000)
    p.add_argument("--tol", type=float, default=1.0e-4)
    p.add_argument("--voxel", type=float, default=0.05)
    p.add_argument("--policy", default="artifacts/gm_loco_student_td/policy.onnx")
    p.add_argument("--out", default="results/mpm_eval/convergence/rheology_iterations_cpu/residuals.jsonl")
    args = p.parse_args()
    for s in args.solvers:
        run(s, args)


if __name__ == "__main__":
    main()
