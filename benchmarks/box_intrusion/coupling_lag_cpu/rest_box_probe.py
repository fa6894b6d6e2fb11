# SPDX-License-Identifier: Apache-2.0
"""CPU probe (the DP-mapping round): where does a 35 kg box placed on dry sand (no drop, no velocity) come to rest?

0.7 x 0.7 x 0.25 m bed, 250 iterations, 0.5 s, 5 and 3 cm voxels; prints the box centre's final and lowest
height [m] and the sinkage [mm] (resting height on the undisturbed surface: 0.1 m).

    uv run python benchmarks/box_intrusion/coupling_lag_cpu/rest_box_probe.py
"""

from __future__ import annotations

import json

import numpy as np

from gmloco.contact import MATERIAL_PRESETS
from gmloco.eval.box.config import BoxCfg
from gmloco.eval.mpm.bed import SandBedCfg
from gmloco.eval.mpm.box_scene import MpmBoxScene, MpmBoxSceneCfg, MpmSolverCfg


def main() -> None:
    """Run both voxel sizes and print one JSON line each."""
    for voxel in (0.05, 0.03):
        cfg = MpmBoxSceneCfg(
            box=BoxCfg(velocity=(0.0, 0.0), drop_height=0.0, duration=0.5),
            bed=SandBedCfg(size_x=0.7, size_y=0.7, depth=0.25, center_x=0.0),
            solver=MpmSolverCfg(voxel_size=voxel, max_iterations=250),
            device="cpu",
            rigid_solver="semi_implicit",
        )
        scene = MpmBoxScene(cfg, [MATERIAL_PRESETS["dry_sand"]])
        scene.run()
        z = np.array([q[0][2] for q in scene.body_q_all])
        row = {"voxel": voxel, "z_end": float(z[-1]), "z_min": float(z.min()), "sinkage_mm": 1e3 * (0.1 - z[-1])}
        print(json.dumps(row | {"particles": scene.particle_count}), flush=True)


if __name__ == "__main__":
    main()
