# SPDX-License-Identifier: Apache-2.0
"""The grid-capacity runs' cost table and figure from the run folders here: ``python benchmarks/mpm_eval/convergence/grid_capacity_solvers/report.py``.

Writes ``throughput.json`` and ``fig_cost.png`` (robot-frames/s per case against the rate the issue's target
needs: 100 ten-second episodes of 2000 frames each in 10 minutes = 333 robot-frames/s).
"""

from __future__ import annotations

import json
import statistics
from pathlib import Path

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/convergence/grid_capacity_solvers"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
FRAMES_10S = 2000  # 10 s of 5 ms frames
TARGET = 100 * FRAMES_10S / 600.0
CASES = [  # (run folder, label, rheology solver, grid capacity factor)
    (
        "h200_v0.03_it500_r32_l1.4_gs_cap3.0",
        "Gauss-Seidel, capacity 3.0 (the accepted-setting runs default)",
        "gs",
        3.0,
    ),
    ("h200_v0.03_it500_r32_l1.4_jacobi", "Jacobi, capacity 3.0", "jacobi", 3.0),
    ("h200_v0.03_it500_r32_l1.4_gs_cap1.5", "Gauss-Seidel, capacity 1.5 (new default)", "gs", 1.5),
    ("h200_v0.03_it500_r32_l1.4_gs_cap1.25", "Gauss-Seidel, capacity 1.25", "gs", 1.25),
    ("table_td_dry_sand", "the 100-episode row, 36 lanes, capacity 1.5", "gs", 1.5),
]


def case(folder: str, label: str, solver: str, capacity: float) -> dict:
    """Robot-frames/s of one run (median over its episodes; the row: its 36-lane part)."""
    rows = [json.loads(line) for line in (HERE / "runs" / folder / "episodes.jsonl").open()]
    lanes = max(r["batch_size"] for r in rows)
    rfs = statistics.median(r["batch_size"] * r["frames_per_s"] for r in rows if r["batch_size"] == lanes)
    return {"run": folder, "label": label, "rheology_solver": solver, "cell_capacity_factor": capacity,
            "robots": lanes, "episodes": len(rows), "robot_frames_per_s": rfs,
            "min_per_100_episodes_10s": 100 * FRAMES_10S / rfs / 60.0}  # fmt: skip


def main() -> None:
    """Write throughput.json and fig_cost.png."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = [case(*c) for c in CASES]
    out = {"device": "NVIDIA H200", "setting": "3 cm voxels, 500 iterations, 5 ms frames, 30 cm bed, 1.4 x 0.6 m "
           "windows", "target_robot_frames_per_s": TARGET, "cases": cases}  # fmt: skip
    (HERE / "throughput.json").write_text(json.dumps(out, indent=1) + "\n")
    fig, ax = plt.subplots(figsize=(7.5, 3.6))
    y = range(len(cases))
    ax.barh(list(y), [c["robot_frames_per_s"] for c in cases], color=["C7", "C7", "C0", "C0", "C2"])
    for k, c in enumerate(cases):
        ax.text(c["robot_frames_per_s"] + 4, k, f"{c['robot_frames_per_s']:.0f} ({c['min_per_100_episodes_10s']:.0f} "
                "min / 100 eps)", va="center", fontsize=8)  # fmt: skip
    ax.axvline(TARGET, color="C3", ls="--", label="target: 100 ten-second episodes in 10 min")
    ax.set_yticks(list(y), [c["label"] for c in cases], fontsize=8)
    ax.invert_yaxis()
    ax.set_xlim(0, TARGET * 1.15)
    ax.set_xlabel("robot-frames per second (H200, 32-36 robots per solver)")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "fig_cost.png", dpi=120)
    plt.close(fig)
    for c in cases:
        print(f"{c['label']}: {c['robot_frames_per_s']:.1f} robot-frames/s, {c['min_per_100_episodes_10s']:.1f} min")


if __name__ == "__main__":
    main()
