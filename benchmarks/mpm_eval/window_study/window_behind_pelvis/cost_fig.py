# SPDX-License-Identifier: Apache-2.0
"""The window-behind-pelvis runs' cost table and figure from the runs' episodes (robot-frames/s = frames/s x lanes, median).

python benchmarks/mpm_eval/window_study/window_behind_pelvis/cost_fig.py   # writes cost.json and fig_cost.png beside this file
"""

from __future__ import annotations

import json
import statistics
from pathlib import Path

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/window_study/window_behind_pelvis"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
TARGET_RF_S = 100 * 10.0 / 0.005 / 600.0
"""Robot-frames/s for 100 ten-second walking episodes (5 ms frames) in 10 minutes."""
CASES = {
    "cost/r32_l1.4_w0.6_d0.3": "1.4 x 0.6 m, bed 30 cm, 32 robots (anchor)",
    "cost/r32_l1.0_w0.5_d0.3": "1.0 x 0.5 m, bed 30 cm, 32 robots",
    "cost/r32_l0.8_w0.5_d0.25": "0.8 x 0.5 m, bed 25 cm, 32 robots",
    "cost/r64_l0.8_w0.5_d0.25": "0.8 x 0.5 m, bed 25 cm, 64 robots",
    "runs/table_ppo_rigid_dry_sand": "ppo_rigid row: 1.0 x 0.5 m, 50 lanes, 10 s",
}


def main() -> None:
    """Write ``cost.json`` and ``fig_cost.png`` beside this file."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = {}
    for rel, label in CASES.items():
        rows = [json.loads(line) for line in (HERE / rel / "episodes.jsonl").read_text().splitlines()]
        rf = statistics.median(r["frames_per_s"] * r["batch_size"] for r in rows)
        out[rel] = {"label": label, "particles": rows[0]["particles"], "lanes": rows[0]["batch_size"],
                    "robot_frames_per_s": round(rf, 1), "min_per_100_walking_episodes": round(200_000 / rf / 60, 1)}  # fmt: skip
    anchor = out["cost/r32_l1.4_w0.6_d0.3"]["robot_frames_per_s"]
    for v in out.values():
        v["x_anchor"] = round(v["robot_frames_per_s"] / anchor, 2)
    (HERE / "cost.json").write_text(json.dumps({"device": "NVIDIA H100 80GB HBM3", "target_robot_frames_per_s":
                                                round(TARGET_RF_S, 1), "cases": out}, indent=1) + "\n")  # fmt: skip
    fig, ax = plt.subplots(figsize=(8, 3.6))
    labels = [v["label"] for v in out.values()]
    vals = [v["robot_frames_per_s"] for v in out.values()]
    ax.barh(labels, vals, color=["0.5", "C0", "C1", "C1", "C2"])
    ax.axvline(TARGET_RF_S, color="C3", ls="--", label=f"target: 100 x 10 s in 10 min ({TARGET_RF_S:.0f})")
    for y, v in enumerate(vals):
        ax.text(v + 4, y, f"{v:.0f}", va="center", fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("robot-frames/s (median, H100, 3 cm / 500 sweeps / 5 ms)")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "fig_cost.png", dpi=130)


if __name__ == "__main__":
    main()
