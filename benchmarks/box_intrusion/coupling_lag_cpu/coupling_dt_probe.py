# SPDX-License-Identifier: Apache-2.0
"""CPU probe (the DP-mapping round): does the MPM box's bounce-back depend on the coupling step (the lagged sand wrench)?

One box-study trial (forward launch, the study's medium of trial ``--trial``, seed 0) in ``MpmBoxScene`` at 5 cm
voxels, with the MPM frame (= coupling) step ``frame_dt`` halved twice while the rigid substep stays 2.5 ms.
Prints one JSON line per setting: box travel, final sinkage, the most negative forward velocity (< 0: the box moved
backwards) and the peak vertical sand force. Deterministic on CPU.

    uv run python benchmarks/box_intrusion/coupling_lag_cpu/coupling_dt_probe.py --trial 4 --out results/box_intrusion/coupling_lag_cpu/trial4.jsonl
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from trial_scene import trial_scene  # this folder: the scripts run as `uv run python <path>`

from gmloco.eval.mpm.box_scene import MpmSolverCfg


def run_one(trial: int, frame_dt: float, substeps: int, voxel: float, iterations: int, duration: float) -> dict:
    """Run one setting and summarise the box's path [m, m/s, N]."""
    solver = MpmSolverCfg(voxel_size=voxel, max_iterations=iterations, frame_dt=frame_dt, rigid_substeps=substeps)
    t0 = time.perf_counter()
    mat, scene = trial_scene(trial, duration, solver)
    scene.run()
    q = np.array([b[0] for b in scene.body_q_all])
    t = frame_dt * np.arange(1, len(q) + 1)
    vx = np.gradient(q[:, 0], t)
    x, y, z, w = q[:, 3], q[:, 4], q[:, 5], q[:, 6]  # body z-axis's world z component from q_xyzw
    tilt = np.degrees(np.arccos(np.clip(1.0 - 2.0 * (x * x + y * y), -1.0, 1.0)))
    pitch_sign = np.sign(2.0 * (x * z + w * y))  # sign of the body z-axis's world x component
    return {
        "trial": trial, "rho_c": mat.rho_c, "mu_int": mat.mu_int, "mu_surf": mat.mu_surf, "frame_dt": frame_dt,
        "rigid_substeps": substeps, "voxel": voxel, "iterations": iterations,
        "travel_m": float(q[-1, 0] - q[0, 0]), "z_end_m": float(q[-1, 2]), "z_min_m": float(q[:, 2].min()),
        "vx_min_mps": float(vx[len(vx) // 10 :].min()), "vx_end_mps": float(vx[-1]),
        "tilt_max_deg": float(tilt.max()), "tilt_end_deg": float(tilt[-1] * pitch_sign[-1]),
        "t_vx_min_s": float(t[len(vx) // 10 + int(np.argmin(vx[len(vx) // 10 :]))]),
        "wall_s": time.perf_counter() - t0,
    }  # fmt: skip


def main() -> None:
    """Run the frame-step ladder for one trial and append the rows to ``--out``."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--trial", type=int, default=4)
    p.add_argument("--voxel", type=float, default=0.05)
    p.add_argument("--iterations", type=int, default=250)
    p.add_argument("--duration", type=float, default=0.6)
    p.add_argument("--frames", default="0.01:4,0.005:2,0.0025:1", help="frame_dt:rigid_substeps list")
    p.add_argument("--out", type=Path, required=True)
    args = p.parse_args()
    for item in args.frames.split(","):
        dt, sub = item.split(":")
        row = run_one(args.trial, float(dt), int(sub), args.voxel, args.iterations, args.duration)
        print(json.dumps(row), flush=True)
        with args.out.open("a") as f:
            f.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
