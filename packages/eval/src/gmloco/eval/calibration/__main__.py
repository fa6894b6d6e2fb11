# SPDX-License-Identifier: Apache-2.0
"""Build a sole calibration dataset from MPM sand (or the 3D-RFT reference); bad input exits 2.

python -m gmloco.eval.calibration --material dry_sand --out results/sand_calibration/dataset/
python -m gmloco.eval.calibration --material dry_sand --out /tmp/calib --smoke --device cpu
python -m gmloco.eval.calibration --material basalt --experiments twist --device cuda:0 --out /tmp/twist

The last records only the yaw-torque probe (``twist``: a loaded sole turned about the vertical) on MPM sand.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace

from gmloco.eval.calibration.build import CalibrationBuildCfg, build_dataset, smoke_build_cfg
from gmloco.eval.calibration.protocol import EXPERIMENTS, PROBE_EXPERIMENTS


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    """Parse the command line."""
    p = argparse.ArgumentParser(prog="python -m gmloco.eval.calibration", description=(__doc__ or "").splitlines()[0])
    p.add_argument("--material", default="dry_sand", help="MATERIAL_PRESETS name")
    p.add_argument("--out", default="results/sand_calibration/dataset", help="output folder of <material>.npz")
    p.add_argument("--sand", choices=["mpm", "rft3d_reference"], default="mpm")
    p.add_argument("--experiments", nargs="+", default=list(EXPERIMENTS), choices=EXPERIMENTS + PROBE_EXPERIMENTS,
                   help="default: every experiment of the fit's datasets; the probes (slide_repress, twist_repress) "
                   "go into a dataset of their own")  # fmt: skip
    p.add_argument("--split-seed", type=int, default=0, help="seed of the fit / held-out split")
    p.add_argument("--voxel-size", type=float, default=None, help="MPM voxel size [m] (default 0.02)")
    p.add_argument("--max-iterations", type=int, default=None, help="MPM rheology iterations (default 250)")
    p.add_argument("--device", default=None, help="Warp device, e.g. cuda:0 or cpu")
    p.add_argument("--smoke", action="store_true", help="tiny bed, coarse voxels, phases shortened 10x (CPU check)")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Run the experiments and write the dataset; return the exit code (2: bad input)."""
    a = parse_args(argv)
    cfg = smoke_build_cfg(a.material, a.out, a.sand) if a.smoke else CalibrationBuildCfg(a.material, a.out, a.sand)
    solver = cfg.mpm.solver
    try:
        if a.voxel_size is not None:
            solver = replace(solver, voxel_size=a.voxel_size)
        if a.max_iterations is not None:
            solver = replace(solver, max_iterations=a.max_iterations)
        mpm = replace(cfg.mpm, solver=replace(solver, frame_dt=cfg.protocol.frame_dt),
                      device=a.device or cfg.mpm.device)  # fmt: skip
        cfg = replace(cfg, experiments=tuple(a.experiments), split_seed=a.split_seed, mpm=mpm)
        path, timings = build_dataset(cfg)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(json.dumps({"dataset": str(path), "timings": timings}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
