# SPDX-License-Identifier: Apache-2.0
"""Session 17's solver rates from the episodes themselves -> ``throughput.json`` and ``fig_lanes.png``.

Each episode line holds its batch's solver rate (``frames_per_s``: MPM frames per second of the whole batch),
particle count, lanes and build time; robot-frames/s while every lane walks = frames/s x lanes. The lanes case
(``runs/cost_r*``: 32 / 50 / 100 robots per solver, 0.3 s episodes) ran at the same time on three GPUs of one
host; the rows' rates are indicative (four processes shared the host).

    python results/mpm_eval/gpu_s17/throughput.py
"""

from __future__ import annotations

import json
import statistics
from pathlib import Path

HERE = Path(__file__).resolve().parent
TARGET_RF_S = 100 * 10.0 / 0.005 / 600.0
"""Robot-frames/s for 100 ten-second walking episodes (5 ms frames) in 10 minutes."""


def _episodes(folder: Path) -> list[dict]:
    """The episode lines of one run folder (empty when it finished none)."""
    path = folder / "episodes.jsonl"
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def _rate(eps: list[dict]) -> dict:
    """Median solver rate, particles, lanes and build time of one run's episodes."""
    fps = statistics.median(e["frames_per_s"] for e in eps)
    lanes = eps[0]["batch_size"]
    rf = fps * lanes
    return {"episodes": len(eps), "particles": eps[0]["particles"], "lanes": lanes,
            "solver_frames_per_s_median": round(fps, 3), "robot_frames_per_s_all_lanes": round(rf, 1),
            "min_per_100_walking_episodes": round(200_000 / rf / 60, 1), "build_s": round(eps[0]["build_s"], 1)}  # fmt: skip


def main() -> None:
    """Write ``throughput.json`` and ``fig_lanes.png`` beside this file."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    manifest = json.loads((HERE / "manifest.json").read_text())
    out = {"device": manifest["device"], "code": manifest["code"], "target_robot_frames_per_s": round(TARGET_RF_S, 1),
           "lanes_case": {}, "rows": {}}  # fmt: skip
    for folder in sorted((HERE / "runs").iterdir()):
        eps = _episodes(folder)
        if not eps:
            continue
        key = "lanes_case" if folder.name.startswith("cost_r") else "rows"
        out[key][folder.name] = _rate(eps)
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
