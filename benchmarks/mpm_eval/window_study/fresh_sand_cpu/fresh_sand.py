# SPDX-License-Identifier: Apache-2.0
"""Issue 9, CPU: does fresh sand carry a sole as aged sand does, and does a wall 5-35 cm away change it?

A recycled window column is seeded stress-free (``kernels_window.eval_window_recycle``) and the G1 evaluation's
rheology solve is warm-started from the particles' stress (Newton picks ``particles`` warm starts for a capped
sparse grid) and stops at 500 sweeps. If fresh sand needed frames to carry its own weight, a sole landing near the
window's front would sink deeper. Here a sole-sized box (0.2 x 0.1 x 0.05 m, 35 kg: a G1 in single stance) is set
on the surface of a 30 cm dry-sand bed at the evaluation's numerics (3 cm voxels, 500 sweeps, 5 ms frames, capped
sparse grid) and its sinkage is logged for 0.3 s:

* ``age``: the bed simulated for that many frames before the box is set down (box held 1 m above);
* ``bed``: the bed's size, i.e. the distance from the box's edges to the bed's frictionless walls.

    python benchmarks/mpm_eval/window_study/fresh_sand_cpu/fresh_sand.py        # ~6 min on 2 CPU cores; writes fresh_sand.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/window_study/fresh_sand_cpu"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

CASES = [  # (name, frames of bed age, bed size x, bed size y [m])
    ("fresh, walls 11-13 cm away", 0, 0.42, 0.36),
    ("aged 40 frames, walls 11-13 cm away", 40, 0.42, 0.36),
    ("fresh, walls 35 / 25 cm away", 0, 0.90, 0.60),
    ("fresh, walls 5 cm away", 0, 0.30, 0.20),
]
FRAMES = 60


def run_case(age: int, size_x: float, size_y: float) -> list[dict[str, float]]:
    """Sinkage [mm] and sand force [N] of the box every 10 frames after it is set down."""
    from gmloco.contact import MATERIAL_PRESETS
    from gmloco.eval.box.config import BoxCfg
    from gmloco.eval.mpm.bed import SandBedCfg
    from gmloco.eval.mpm.box_scene import MpmBoxScene, MpmBoxSceneCfg, MpmSolverCfg

    cfg = MpmBoxSceneCfg(
        box=BoxCfg(size=(0.2, 0.1, 0.05), mass=35.0, drop_height=0.0, velocity=(0.0, 0.0), duration=0.3),
        bed=SandBedCfg(size_x=size_x, size_y=size_y, depth=0.3, center_x=0.0),
        solver=MpmSolverCfg(
            voxel_size=0.03,
            frame_dt=0.005,
            rigid_substeps=1,
            max_iterations=500,
            max_active_cell_count=round(4 * size_x * size_y * 0.36 / 0.03**3),  # padding only (the solve sweeps it)
        ),
        device="cpu",
        rigid_solver="semi_implicit",
    )
    sc = MpmBoxScene(cfg, MATERIAL_PRESETS["dry_sand"])
    assert sc.mpm._stress_warmstart == "particles"  # as in the G1 evaluation's capped sparse grid
    b = sc.box_body
    rest = sc.state_0.body_q.numpy()[b].copy()

    def place(z: float) -> None:
        for st in (sc.state_0, sc.state_1):
            q, qd = st.body_q.numpy(), st.body_qd.numpy()
            q[b], q[b, 2], qd[b] = rest, z, 0.0
            st.body_q.assign(q)
            st.body_qd.assign(qd)
        sc.sand_wrench.zero_()

    for _ in range(age):
        place(rest[2] + 1.0)
        sc.step()
    place(rest[2])
    out = []
    for f in range(1, FRAMES + 1):
        sc.step()
        if f % 10 == 0:
            z = float(sc.state_0.body_q.numpy()[b, 2])
            out.append({"frame": f, "sinkage_mm": round(1000 * (float(rest[2]) - z), 2),
                        "sand_fz_n": round(float(sc.sand_force_all[-1][0, 2]), 1)})  # fmt: skip
    return out


def main() -> None:
    """Run every case and write ``fresh_sand.json`` beside this file."""
    results = {}
    for name, age, sx, sy in CASES:
        results[name] = {"age_frames": age, "bed_m": [sx, sy], "log": run_case(age, sx, sy)}
        print(name, results[name]["log"][-1], flush=True)
    path = RESULTS_HOME / "fresh_sand.json"
    path.write_text(json.dumps({"cmd": " ".join(sys.argv), "cases": results}, indent=1) + "\n")


if __name__ == "__main__":
    main()
