# SPDX-License-Identifier: Apache-2.0
"""CPU probe: MPM force on a horizontal plate pressed from the free surface (0-10 cm), against PNAS 3D-RFT.

The plate calibration of ``MATERIAL_MAPPING_DIAGNOSIS.md`` section 6 samples 6-16 cm of centroid depth after 5 cm of
travel. A walking G1 sole works in the first few centimetres, starting from a fresh surface. This probe pushes a
10 x 10 x 2 cm plate (``gmloco.eval.rft_fit.plate.run_plate_intrusion``) straight down from just above the surface
of dry sand (new mapping, ``mpm_material``) and logs F_z against the centroid depth d, next to the PNAS 3D-RFT value
F = G_z xi_n A d (G_z = 0.876). Appends one JSON record per run to ``--log``.

    uv run python benchmarks/mpm_eval/probes/dig_in_cpu/shallow_plate.py --label plate_v5_i50 --voxel 0.05 --iterations 50
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from gmloco.contact.materials import MATERIAL_PRESETS, xi_n
from gmloco.eval.mpm.bed import SandBedCfg
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.rft_fit.plate import PlateIntrusionCfg, run_plate_intrusion

G_Z_PNAS = 0.876
"""PNAS 3D-RFT G_z of a horizontal plate moving straight down."""


def main() -> None:
    """Run one shallow intrusion and append its record."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--label", required=True)
    p.add_argument("--voxel", type=float, default=0.05)
    p.add_argument("--iterations", type=int, default=50)
    p.add_argument("--grid", choices=("sparse", "dense"), default="sparse")
    p.add_argument("--speed", type=float, default=0.3, help="intrusion speed [m/s]")
    p.add_argument("--log", type=Path, default=Path("results/mpm_eval/probes/dig_in_cpu/runs.jsonl"))
    args = p.parse_args()

    t0 = time.time()
    m = MATERIAL_PRESETS["dry_sand"]
    size, thick = 0.1, 0.02
    cfg = PlateIntrusionCfg(
        plate_size=size, plate_thickness=thick, speed=args.speed, depth_range=(0.0, 0.10),
        travel_before_sampling=thick / 2 + 0.005,  # start with the plate's bottom 5 mm above the surface
        bed=SandBedCfg(size_x=0.5, size_y=0.5, depth=0.3, center_x=0.0),
        solver=MpmSolverCfg(voxel_size=args.voxel, max_iterations=args.iterations, grid_type=args.grid),
    )  # fmt: skip
    run = run_plate_intrusion(cfg, m, np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, -1.0]))
    area = size * size
    k_rft = G_Z_PNAS * float(xi_n(m.rho_c, m.mu_int)) * area  # N per m of centroid depth
    rows = []
    # depth bins of the centroid: the MPM force oscillates as the plate crosses voxel faces, so average per bin
    for lo, hi in ((0.005, 0.025), (0.025, 0.05), (0.05, 0.075), (0.075, 0.10)):
        sel = (run.depth >= lo) & (run.depth < hi)
        if sel.any():
            f, d = float(np.mean(run.force[sel, 2])), float(np.mean(run.depth[sel]))
            rows.append(dict(depth=[lo, hi], fz_mpm=round(f, 1), fz_rft=round(k_rft * d, 1), ratio=round(f / (k_rft * d), 3),
                             fz_min=round(float(np.min(run.force[sel, 2])), 1), fz_max=round(float(np.max(run.force[sel, 2])), 1)))  # fmt: skip
    rec = dict(
        label=args.label, kind="shallow_plate", voxel=args.voxel, iterations=args.iterations, grid=args.grid,
        speed=args.speed, particles=run.particle_count, k_rft_n_per_m=round(k_rft, 1), rows=rows,
        s=round(time.time() - t0, 1),
    )  # fmt: skip
    with args.log.open("a") as f:
        f.write(json.dumps(rec) + "\n")
    for r in rows:
        print(args.label, r, flush=True)
    print(args.label, {k: v for k, v in rec.items() if k != "rows"}, flush=True)


if __name__ == "__main__":
    main()
