# SPDX-License-Identifier: Apache-2.0
"""Wall-clock cost of one MPM frame against the particles in the solve, and the time-box fit's model of it (issue 9).

Reads every run of the square- and reach-window rows (``FOLDERS``) whose episodes carry the wall clock (``elapsed_s``, ``end_frame``), takes each
scene's stretch with all its lanes walking (``gmloco.eval.studies.run_rates.running_rates``) and pools the frames and seconds
per built size (particles, lanes). Fits ``frame_s = a + b * particles`` and compares it with the model
``gmloco.eval.g1.cost`` uses to fit cells into a time box: a measured full cell's frame, scaled by lanes above
``FRAME_COST_FLOOR``. Writes ``frame_cost.json`` and ``fig_frame_cost.png`` beside this script.

    python benchmarks/mpm_eval/frame_cost.py
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from gmloco.eval.g1.cost import FRAME_COST_FLOOR, CellCost, frame_seconds
from gmloco.eval.metrics.episodes import read_episodes
from gmloco.eval.studies.run_rates import has_wall_clock, running_rates, scenes

MPM_RESULTS = Path(__file__).resolve().parents[2] / "results" / "mpm_eval"  # the runs read, the outputs written
FOLDERS = (  # the row folders whose episodes carry the wall clock
    "table_rows/dry_sand_square_window",
    "table_rows/poppy_seed_deep_sand_reach",
    "table_rows/basalt_rough_square_window",
    "table_rows/last_rows_retire_lanes",
)


def points() -> list[dict[str, float]]:
    """One point per built size: particles, lanes, frames, seconds and seconds per frame (all lanes walking)."""
    pooled: dict[tuple[int, int], list[float]] = {}
    for folder in FOLDERS:
        for path in sorted((MPM_RESULTS / folder / "runs").glob("*/episodes.jsonl")):
            for scene in scenes(read_episodes(path)):
                if not all(has_wall_clock(e) for e in scene):
                    continue
                lanes = int(scene[0]["batch_size"])
                rates = running_rates(scene)
                if lanes in rates:
                    acc = pooled.setdefault((int(scene[0]["particles"]), lanes), [0.0, 0.0])
                    acc[0] += rates[lanes][0]
                    acc[1] += rates[lanes][1]
    return [{"particles": p, "lanes": n, "frames": f, "seconds": s, "frame_s": s / f}
            for (p, n), (f, s) in sorted(pooled.items())]  # fmt: skip


def main() -> None:
    """Fit, compare with the time-box model, write the JSON and the figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pts = points()
    x = np.array([p["particles"] for p in pts]) / 1e6
    y = np.array([p["frame_s"] for p in pts])
    w = np.sqrt([p["frames"] for p in pts])
    b, a = np.polyfit(x, y, 1, w=w)
    full = max(pts, key=lambda p: p["particles"])
    cost = CellCost(lanes=int(full["lanes"]), frame_s=full["frame_s"], build_s=0.0)
    per_lane = full["particles"] / full["lanes"] / 1e6
    model = {n: frame_seconds(cost, n) for n in range(1, int(full["lanes"]) + 1)}
    doc = {
        "folders": FOLDERS,
        "clock": "wall (elapsed_s, end_frame); all lanes of a scene walking",
        "points": [{k: round(v, 4) for k, v in p.items()} for p in pts],
        "fit": {"frame_s_at_zero": round(float(a), 4), "frame_s_per_million_particles": round(float(b), 4)},
        "fit_floor_share_of_largest": round(float(a / full["frame_s"]), 3),
        "model_floor": FRAME_COST_FLOOR,
        "model_over_fit": {
            str(n): round(float(model[n] / (a + b * per_lane * n)), 3) for n in (1, 3, 6, 12, 18, 25) if n in model
        },
    }
    (MPM_RESULTS / "frame_cost.json").write_text(json.dumps(doc, indent=1) + "\n")
    fig, ax = plt.subplots(figsize=(6.4, 4.2), constrained_layout=True)
    ax.scatter(x, y, s=20 + 0.05 * np.array([p["frames"] for p in pts]), label="measured (size: frames pooled)")
    xs = np.linspace(0.0, x.max() * 1.05, 50)
    ax.plot(xs, a + b * xs, "C0--", label=f"fit: {a:.3f} s + {b:.3f} s per million particles")
    lanes = np.arange(1, int(full["lanes"]) + 1)
    ax.plot(lanes * per_lane, [model[n] for n in lanes], "C3-",
            label=f"time-box model of a {full['lanes']}-lane cell (floor {FRAME_COST_FLOOR:.0%})")  # fmt: skip
    for p in pts:
        ax.annotate(f"{p['lanes']} lanes", (p["particles"] / 1e6, p["frame_s"]), textcoords="offset points",
                    xytext=(4, -10), fontsize=7)  # fmt: skip
    ax.set_xlabel("particles in the solve [million]")
    ax.set_ylabel("wall-clock seconds per MPM frame")
    ax.set_title("H200, 3 cm, 500 sweeps, 5 ms frames (runs with the wall clock)", fontsize=9)
    ax.set_xlim(0, None)
    ax.set_ylim(0, None)
    ax.legend(fontsize=7, loc="upper left")
    fig.savefig(MPM_RESULTS / "fig_frame_cost.png", dpi=130)
    print(json.dumps(doc["fit"]), "model/fit by lanes:", doc["model_over_fit"])


if __name__ == "__main__":
    main()
