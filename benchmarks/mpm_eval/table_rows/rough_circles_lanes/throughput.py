# SPDX-License-Identifier: Apache-2.0
"""The rough-and-circles runs' solver rates from the episodes themselves -> ``throughput.json`` and ``fig_lanes.png``.

Each episode line holds its batch's solver rate (``frames_per_s``: MPM frames per second of the whole batch),
particle count, lanes and build time; robot-frames/s while every lane walks = frames/s x lanes. The lanes case
(``runs/cost_r*``: 32 / 50 / 100 robots per solver, 0.3 s episodes) ran at the same time on three GPUs of one
host; the rows' rates are indicative (four processes shared the host).

    python benchmarks/mpm_eval/table_rows/rough_circles_lanes/throughput.py
"""

from __future__ import annotations

import json
from pathlib import Path

from gmloco.eval.metrics.episodes import read_episodes
from gmloco.eval.studies.run_rates import TARGET_ROBOT_FRAMES_PER_S as TARGET_RF_S
from gmloco.eval.studies.run_rates import run_rate

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/table_rows/rough_circles_lanes"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME


def main() -> None:
    """Write ``throughput.json`` and ``fig_lanes.png`` beside this file."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    manifest = json.loads((HERE / "manifest.json").read_text())
    out = {"device": manifest["device"], "code": manifest["code"], "target_robot_frames_per_s": round(TARGET_RF_S, 1),
           "lanes_case": {}, "rows": {}}  # fmt: skip
    for folder in sorted((HERE / "runs").iterdir()):
        eps = read_episodes(folder / "episodes.jsonl") if (folder / "episodes.jsonl").exists() else []
        if not eps:
            continue
        key = "lanes_case" if folder.name.startswith("cost_r") else "rows"
        out[key][folder.name] = run_rate(eps)
        print(folder.name, out[key][folder.name])
    (HERE / "throughput.json").write_text(json.dumps(out, indent=1) + "\n")
    cases = sorted(out["lanes_case"].values(), key=lambda v: v["lanes"])
    if not cases:
        return
    fig, ax = plt.subplots(figsize=(5.5, 3.4))
    lanes = [c["lanes"] for c in cases]
    ax.plot(lanes, [c["robot_frames_per_s_all_lanes"] for c in cases], "o-", label="measured (H100, side by side)")
    for c in cases:
        ax.annotate(f"{c['robot_frames_per_s_all_lanes']:.0f}", (c["lanes"], c["robot_frames_per_s_all_lanes"]),
                    textcoords="offset points", xytext=(4, -12), fontsize=8)  # fmt: skip
    ax.axhline(TARGET_RF_S, color="C3", ls="--", label=f"target: 100 x 10 s in 10 min ({TARGET_RF_S:.0f})")
    ax.set_xlabel("robots per MPM solver (lanes)")
    ax.set_ylabel("robot-frames/s")
    ax.set_ylim(0, TARGET_RF_S * 1.15)
    ax.set_title("3 cm / 500 sweeps / 5 ms, 1.4 x 0.6 m window, dry sand", fontsize=9)
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "fig_lanes.png", dpi=130)


if __name__ == "__main__":
    main()
