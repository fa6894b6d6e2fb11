# SPDX-License-Identifier: Apache-2.0
"""GPU probe (the dig-in probes): 3D-RFT G of two 10 cm plates in MPM sand at several ``mpm:friction`` values.

The horizontal plate is pushed straight down (G_z), the vertical plate dragged along +x (G_x); 0.6 x 0.6 x 0.3 m
bed, 2 cm voxels, 1000 iterations, samples at 6-16 cm (the 36-plate fit's numerics). Each argument after the
preset name is ``field=value`` of ``MpmMaterialCfg`` replacing the mapped value, e.g.

    python3 benchmarks/mpm_eval/probes/material_mapping_gpu/friction_probe.py dry_sand friction=0.6 friction=0.717 dilatancy=0.3

It ran before ``mpm_material`` switched to ``drucker_prager_friction``; ``friction=<mu_int>`` reproduces the old
mapping. Prints one JSON line per plate.
"""

from __future__ import annotations

import dataclasses
import json
import sys

from gmloco.contact import MATERIAL_PRESETS
from gmloco.eval.mpm.bed import SandBedCfg
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.materials import mpm_material
from gmloco.eval.rft_fit.plate import PlateIntrusionCfg, run_plate_intrusions
from gmloco.eval.rft_fit.run import RftFitCfg, plate_directions
from gmloco.eval.rft_fit.steady import plate_record


def main(argv: list[str]) -> None:
    """Run the two plates once per override and print their G [-]."""
    name, overrides = argv[0], argv[1:]
    mat = MATERIAL_PRESETS[name]
    plate = PlateIntrusionCfg(
        depth_range=(0.06, 0.16), travel_before_sampling=0.06,
        bed=SandBedCfg(size_x=0.6, size_y=0.6, depth=0.3, center_x=0.0),
        solver=MpmSolverCfg(voxel_size=0.02, max_iterations=1000),
    )  # fmt: skip
    fit_cfg = RftFitCfg(out_dir=".", plate=plate, gamma_deg=(90.0, 0.0), beta_deg=(0.0, 90.0), psi_deg=(0.0,))
    dirs = plate_directions(fit_cfg)
    for key in overrides:
        field, value = key.split("=")
        mpm = dataclasses.replace(mpm_material(mat), **{field: float(value)})
        runs = run_plate_intrusions(plate, mpm, [(n, v) for _, n, v in dirs])
        for (angles, _, _), run in zip(dirs, runs, strict=True):
            rec = plate_record(run, plate, mat.xi, angles, mat.mu_surf, 0.05)
            g = [round(x, 4) for x in rec["G"]]
            print(json.dumps({"material": name, "override": key, "angles": angles, "G": g}), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
