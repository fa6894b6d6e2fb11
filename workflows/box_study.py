# SPDX-License-Identifier: Apache-2.0
"""Box-intrusion study (issue 5): thin CLI around ``gmloco.eval.box.study.run``.

Resumable and time-boxed (call it again with the same ``--out-dir`` to continue); runs with plain python::

    PYTHONPATH=packages/contact/src:packages/eval/src python workflows/box_study.py \
        --num-trials 30 --voxel-size 0.03 --max-minutes 8 --out-dir results/box_intrusion/main

Box-size check: ``--variants forward size_x0.7 size_x1.4`` (same 35 kg, footprint scaled). Voxel convergence:
run the same ``--seed``/``--num-trials`` into one directory per ``--voxel-size``, then
``--convergence DIR_5cm DIR_3cm DIR_2cm`` writes ``<out-dir>/convergence.json`` (a level whose MPM solve failed is
listed under ``failed_levels`` with the error of ``DIR.log``). A failed MPM solve is logged to
``mpm_failures.jsonl`` and skipped; ``summary.json`` holds ``lateral_impact`` (peak / impulse of the lateral force).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

__all__ = ["main"]


def main() -> None:
    """Parse the command line, run the study (or the convergence comparison), print the summary."""
    from gmloco.eval.box.study import BoxStudyCfg, box_study_smoke_cfg, run
    from gmloco.eval.mpm.bed import SandBedCfg
    from gmloco.eval.mpm.box_scene import MpmSolverCfg

    p = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    p.add_argument("--out-dir", default="results/box_intrusion")
    p.add_argument("--num-trials", type=int, default=30)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--voxel-size", type=float, default=0.03, help="MPM voxel [m]")
    p.add_argument("--max-iterations", type=int, default=250, help="MPM rheology iterations (>= 25)")
    p.add_argument("--max-active-cells", type=int, default=-1, help="MPM active-cell capacity (fixed grid)")
    p.add_argument("--grid-type", default="sparse", choices=["sparse", "fixed", "dense"])
    p.add_argument("--mpm-batch", type=int, default=1, help="MPM trials per solve (GPU: ~10)")
    p.add_argument("--rigid-solver", default="semi_implicit", choices=["semi_implicit", "mujoco"])
    p.add_argument("--bed", type=float, nargs=3, default=[1.2, 0.8, 0.3], help="bed x, y, depth [m]")
    p.add_argument("--duration", type=float, default=1.0, help="simulated time per trial [s]")
    p.add_argument("--models", nargs="+", default=None, help="subset of: mpm rigid heuristic_rft cone_single ...")
    p.add_argument("--variants", nargs="+", default=["forward", "lateral"], help="forward lateral size_x<scale>")
    p.add_argument("--fitted-coeffs", default="", help="results/rft_fit/.../rft3d_fitted.json to add rft3d_fitted")
    p.add_argument("--box-size", type=float, nargs=3, default=[0.3, 0.3, 0.2])
    p.add_argument("--max-minutes", type=float, default=60.0)
    p.add_argument("--device", default=None)
    p.add_argument(
        "--handover",
        default="predict",
        choices=["predict", "rewind", "actual"],
        help="MPM coupling: collider velocity MPM sees (MpmSolverCfg.velocity_handover)",
    )
    p.add_argument(
        "--max-leaked-fraction",
        type=float,
        default=1.0e-4,
        help="stray particles below the floor a trial may leave (fraction of its particles)",
    )
    p.add_argument("--no-figure", action="store_true")
    p.add_argument("--convergence", nargs="+", default=None, help="study dirs at different voxel sizes")
    p.add_argument("--smoke", action="store_true", help="CPU smoke: 1 trial, tiny bed, 0.2 s")
    a = p.parse_args()
    if a.convergence:
        from gmloco.eval.box.checks import write_voxel_convergence

        print(json.dumps(write_voxel_convergence(a.convergence, Path(a.out_dir) / "convergence.json"), indent=1))
        return
    if a.smoke:
        cfg = box_study_smoke_cfg(a.out_dir)
    else:
        base = BoxStudyCfg()
        box = replace(base.box, duration=a.duration, size=tuple(a.box_size))
        mpm = MpmSolverCfg(voxel_size=a.voxel_size, grid_type=a.grid_type, max_active_cell_count=a.max_active_cells,
                           max_iterations=a.max_iterations, velocity_handover=a.handover)  # fmt: skip
        cfg = replace(
            base, out_dir=a.out_dir, num_trials=a.num_trials, seed=a.seed, variants=tuple(a.variants), box=box,
            rom=replace(base.rom, box=box), bed=SandBedCfg(size_x=a.bed[0], size_y=a.bed[1], depth=a.bed[2]),
            mpm=mpm, rft3d_fitted_coeffs=a.fitted_coeffs, max_minutes=a.max_minutes, device=a.device,
            rigid_solver=a.rigid_solver, make_figure=not a.no_figure, mpm_batch=a.mpm_batch,
            mpm_max_leaked_fraction=a.max_leaked_fraction,
        )  # fmt: skip
    if a.models:
        cfg = replace(cfg, models=tuple(a.models))
    print(json.dumps(run(cfg), indent=1))


if __name__ == "__main__":
    main()
