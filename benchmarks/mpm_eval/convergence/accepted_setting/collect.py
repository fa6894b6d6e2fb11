# SPDX-License-Identifier: Apache-2.0
"""Gather the accepted-setting runs' device chunks into this folder (issue 9).

    python benchmarks/mpm_eval/convergence/accepted_setting/collect.py DEVICE:CHUNKS_DIR [DEVICE:CHUNKS_DIR ...]

``CHUNKS_DIR/sweep12/<case>/episodes.jsonl`` (0.5-1.5 s cost cases) become one row each of ``sweep.jsonl`` (the
case's window, bed, voxel, iterations, robots, particles, frames per second and the robot-frames per second they
make), tagged with DEVICE (``h100`` or ``h200``). ``CHUNKS_DIR/g1_eval/<run>/`` (5 s and 10 s episodes) are copied to
``runs/<run>/`` (episodes, summary, tables). Existing rows and runs are replaced.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/convergence/accepted_setting"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
KEEP = ("episodes.jsonl", "summary.json", "table_terrains.md", "table_speeds.md")
FRAMES_10S = 2000
"""Frames of a 10 s episode at 5 ms."""


def sweep_row(case: Path, device: str) -> dict:
    """One cost case: configuration from its summary, timings from its first episode."""
    cfg = json.loads((case / "summary.json").read_text())["cfg"]
    ep = json.loads((case / "episodes.jsonl").read_text().splitlines()[0])
    win, sol = cfg["window"], cfg["solver"]
    robot_fps = ep["batch_size"] * ep["frames_per_s"]
    return {
        "case": case.name, "device": device, "robots": ep["batch_size"], "particles": ep["particles"],
        "window_length_m": win["length"], "window_width_m": win["width"], "bed_depth_m": cfg["bed_depth"],
        "voxel_m": sol["voxel_size"], "iterations": sol["max_iterations"], "rheology_solver": sol["rheology_solver"],
        "build_s": ep["build_s"], "frames_per_s": ep["frames_per_s"], "robot_frames_per_s": robot_fps,
        "min_per_100_episodes_10s": 100 * FRAMES_10S / robot_fps / 60.0,
    }  # fmt: skip


def main(args: list[str]) -> None:
    """Merge the chunks' cost cases into ``sweep.jsonl`` and copy their runs."""
    path = HERE / "sweep.jsonl"
    rows = {r["case"]: r for r in map(json.loads, path.read_text().splitlines())} if path.exists() else {}
    for arg in args:
        device, _, d = arg.partition(":")
        if device not in ("h100", "h200") or not d:
            raise SystemExit(f"{arg}: expected DEVICE:CHUNKS_DIR with DEVICE h100 or h200")
        for case in sorted(Path(d).glob("sweep12/*/episodes.jsonl")):
            row = sweep_row(case.parent, device)
            rows[row["case"]] = row
        for run in sorted(p.parent for p in Path(d).glob("g1_eval/*/episodes.jsonl")):
            dst = HERE / "runs" / run.name
            dst.mkdir(parents=True, exist_ok=True)
            for name in KEEP:
                if (run / name).exists():
                    shutil.copy2(run / name, dst / name)
    path.write_text("".join(json.dumps(r) + "\n" for r in rows.values()))
    print(f"{len(rows)} cost cases in {path.name}; runs: {len(list((HERE / 'runs').iterdir()))}")


if __name__ == "__main__":
    main(sys.argv[1:])
