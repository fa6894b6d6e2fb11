# SPDX-License-Identifier: Apache-2.0
"""CPU probe of issue 5's 2 cm failure: does one box trial leak sand through the floor (single region)?

Usage: ``uv run python benchmarks/box_intrusion/gpu/cpu_probe_v0.02/leak2cm.py VOXEL TRIAL FRAMES`` (trial t's
medium from the study's seed 0; 0.8 x 0.6 x 0.3 m bed, 250 iterations); prints the box pose and the particles
below the floor every 5 frames.
"""

from __future__ import annotations

import sys
import time
from dataclasses import replace

from gmloco.contact import MaterialCfg
from gmloco.eval.box.config import BoxCfg
from gmloco.eval.box.study import BoxStudyCfg, sample_media
from gmloco.eval.mpm.bed import SandBedCfg
from gmloco.eval.mpm.box_scene import MpmBoxScene, MpmBoxSceneCfg, MpmSolverCfg


def main() -> None:
    """Run one trial and print the floor diagnostics."""
    voxel, trial, frames = float(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    media = sample_media(replace(BoxStudyCfg(), num_trials=5))
    mat = MaterialCfg(*(float(media[k][trial]) for k in ("bulk_density", "packing", "mu_int", "mu_surf")))
    cfg = MpmBoxSceneCfg(
        box=BoxCfg(duration=0.6),
        bed=SandBedCfg(size_x=0.8, size_y=0.6, depth=0.3, center_x=0.2),
        solver=MpmSolverCfg(voxel_size=voxel, max_iterations=250),
        device="cpu",
        rigid_solver="semi_implicit",
    )
    scene = MpmBoxScene(cfg, [mat])
    print("particles", scene.particle_count, "medium", mat, flush=True)
    t0 = time.perf_counter()
    for f in range(frames):
        scene.step()
        if f % 5 == 4 or f == frames - 1:
            d = scene.diagnostics()
            q = scene.body_q_all[-1][0]
            below = int((scene.sand_state.particle_q.numpy()[:, 2] < -cfg.bed.depth).sum())
            print(f"frame {f + 1} t={time.perf_counter() - t0:.0f}s box x={q[0]:.3f} z={q[2]:.3f} "
                  f"zmin={d['particle_z_min']:.4f} leaked={d['leaked_particles']} below_floor={below}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
