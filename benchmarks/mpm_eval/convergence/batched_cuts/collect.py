# SPDX-License-Identifier: Apache-2.0
"""Gather the batched-cuts runs' device chunks into this folder (issue 9).

    python benchmarks/mpm_eval/convergence/batched_cuts/collect.py CHUNKS_DIR [CHUNKS_DIR ...]

``CHUNKS_DIR/sweep*/<case>/episodes.jsonl`` (0.5 s cost cases) become one row each of ``sweep.jsonl``: the case's
window, bed depth, voxel, iterations, robots per solver, particles, build time and frames per second, with the
10 s episodes per minute they imply. ``CHUNKS_DIR/g1_eval/<run>/`` (10 s episodes) are copied to ``runs/<run>/``
(episodes, summary, tables; figures and recordings stay behind). Existing rows and runs are replaced.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/convergence/batched_cuts"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
KEEP = ("episodes.jsonl", "summary.json", "table_terrains.md", "table_speeds.md")


def sweep_row(case: Path) -> dict:
    """One cost case: configuration from its summary, timings from its first episode."""
    cfg = json.loads((case / "summary.json").read_text())["cfg"]
    ep = json.loads((case / "episodes.jsonl").read_text().splitlines()[0])
    frames_10s = round(10.0 / cfg["solver"]["frame_dt"])
    batch_s = ep["build_s"] + frames_10s / ep["frames_per_s"]
    win = cfg["window"]
    return {
        "case": case.name, "sweep": case.parent.name, "robots": ep["batch_size"], "particles": ep["particles"],
        "window_length_m": win["length"], "window_width_m": win["width"], "window_lead_m": win["lead"],
        "particles_per_voxel": win["particles_per_voxel"], "bed_depth_m": cfg["bed_depth"],
        "voxel_m": cfg["solver"]["voxel_size"], "iterations": cfg["solver"]["max_iterations"],
        "frame_dt_s": cfg["solver"]["frame_dt"], "build_s": ep["build_s"],
        "frames_per_s": ep["frames_per_s"], "particle_frames_per_s": ep["particles"] * ep["frames_per_s"],
        "episodes_per_min_10s": 60.0 * ep["batch_size"] / batch_s,
    }  # fmt: skip


def main(dirs: list[str]) -> None:
    """Merge the chunks' cost cases into ``sweep.jsonl`` and copy their 10 s runs."""
    path = HERE / "sweep.jsonl"
    rows = {r["case"]: r for r in map(json.loads, path.read_text().splitlines())} if path.exists() else {}
    for d in map(Path, dirs):
        for case in sorted(d.glob("sweep*/*/episodes.jsonl")):
            row = sweep_row(case.parent)
            rows[row["case"]] = row
        for run in sorted(p.parent for p in d.glob("g1_eval/*/episodes.jsonl")):
            dst = HERE / "runs" / run.name
            dst.mkdir(parents=True, exist_ok=True)
            for name in KEEP:
                if (run / name).exists():
                    shutil.copy2(run / name, dst / name)
    path.write_text("".join(json.dumps(r) + "\n" for r in rows.values()))
    print(f"{len(rows)} cost cases in {path.name}; runs: {sorted(p.name for p in (HERE / 'runs').iterdir())}")


if __name__ == "__main__":
    main(sys.argv[1:])
