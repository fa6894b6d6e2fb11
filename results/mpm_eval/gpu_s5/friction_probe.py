"""Scratch (session 5): horizontal plate down + wall along x in MPM dry sand at several mpm:friction values."""
import json, sys, numpy as np
from gmloco.contact import MATERIAL_PRESETS
from gmloco.eval.mpm.bed import SandBedCfg
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.materials import mpm_material
from gmloco.eval.rft_fit.plate import PlateIntrusionCfg, run_plate_intrusions
from gmloco.eval.rft_fit.run import RftFitCfg, plate_directions
from gmloco.eval.rft_fit.steady import plate_record
mat = MATERIAL_PRESETS[sys.argv[1]]
plate = PlateIntrusionCfg(depth_range=(0.06, 0.16), travel_before_sampling=0.06,
    bed=SandBedCfg(size_x=0.6, size_y=0.6, depth=0.3, center_x=0.0), solver=MpmSolverCfg(voxel_size=0.02, max_iterations=1000))
dirs = plate_directions(RftFitCfg(out_dir=".", plate=plate, gamma_deg=(90.0, 0.0), beta_deg=(0.0, 90.0), psi_deg=(0.0,)))
for key in sys.argv[2:]:
    k, v = key.split("=")
    m = mpm_material(mat, **{k: float(v)}) if k != "friction" else mpm_material(mat)
    if k == "friction":
        import dataclasses; m = dataclasses.replace(m, friction=float(v))
    res = run_plate_intrusions(plate, m, [(n, vv) for _, n, vv in dirs])
    for (ang, _, _), r in zip(dirs, res):
        rec = plate_record(r, plate, mat.xi, ang, mat.mu_surf, 0.05)
        print(json.dumps({"material": sys.argv[1], "override": key, "angles": ang, "G": [round(g, 4) for g in rec["G"]]}), flush=True)
