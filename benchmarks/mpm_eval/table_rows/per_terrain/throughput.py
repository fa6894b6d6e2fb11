# SPDX-License-Identifier: Apache-2.0
"""Per-row solver rates of the per-terrain runs' four-GPU run, from the episodes themselves -> ``throughput.json``.

Each episode line holds its batch's solver rate (``frames_per_s``: MPM frames per second of the whole batch),
particle count, lanes and build time; robot-frames/s while every lane walks = frames/s x lanes. Indicative only:
four processes shared one host (``README.md`` section 4).

    python benchmarks/mpm_eval/table_rows/per_terrain/throughput.py
"""

from __future__ import annotations

import json
import statistics
from pathlib import Path

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/table_rows/per_terrain"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME


def main() -> None:
    """Median rate, particles, lanes and build time of every run folder."""
    out = {"device": "NVIDIA H100 80GB HBM3 x 4 (one process per GPU, shared host)", "code": "main at cf4448a",
           "rows": {}}  # fmt: skip
    for folder in sorted((HERE / "runs").iterdir()):
        eps = [json.loads(line) for line in (folder / "episodes.jsonl").read_text().splitlines() if line.strip()]
        fps = statistics.median(e["frames_per_s"] for e in eps)
        lanes = eps[0]["batch_size"]
        out["rows"][folder.name] = {
            "episodes": len(eps), "particles": eps[0]["particles"], "lanes": lanes,
            "solver_frames_per_s_median": round(fps, 3), "robot_frames_per_s_all_lanes": round(fps * lanes, 1),
            "build_s": round(eps[0]["build_s"], 1),
        }  # fmt: skip
        print(folder.name, out["rows"][folder.name])
    (HERE / "throughput.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
