# SPDX-License-Identifier: Apache-2.0
"""Fresh out-of-library test episodes for the residual-floor rule (PROTOCOL.md); seeds no earlier episode used.

uv run python benchmarks/mismatch_benchmark/ool/run_ool.py   # writes rows/ and summary.json next to this file
"""

from __future__ import annotations

import json
import os
import sys
import time
from multiprocessing import Pool
from pathlib import Path

from gmloco.deploy.mismatch.benchmark.episodes import OOL, SAND_OOL
from gmloco.deploy.mismatch.benchmark.sweep import run_episode

RESULTS_HOME = Path(__file__).resolve().parents[3] / "results/mismatch_benchmark/ool"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

OUT = RESULTS_HOME
SAND = {"ground": "sand", "material": "dry_sand", "policy": True, "odometry": True}


def episodes() -> list[tuple[dict, float]]:
    """Plane OOL at seeds 301-302 (9 s stepping), sand OOL at seeds 2101-2102 (8 s walking policy)."""
    eps = []
    for seed in (301, 302):
        for eid, p in OOL.items():
            eps.append(({"name": f"{eid}-s{seed}", "effect": eid, "params": p, "strength": "mid", "seed": seed}, 9.0))
    for seed in (2101, 2102):
        for eid, p in SAND_OOL.items():
            ep = {"name": f"sand-{eid}-s{seed}", "effect": eid, "params": p, "strength": "mid", "seed": seed}
            eps.append(({**ep, **SAND}, 8.0))
    return eps


def _one(arg: tuple[dict, float]) -> dict:
    """Run one episode, keeping the sweep alive on failure."""
    ep, duration = arg
    try:
        return run_episode(ep, str(OUT), duration, None, None)
    except Exception as exc:  # the row records the failure
        return {**ep, "error": repr(exc)}


if __name__ == "__main__":
    only = sys.argv[1].split(",") if len(sys.argv) > 1 else None
    todo = [e for e in episodes() if only is None or any(e[0]["name"].startswith(s) for s in only)]
    t0 = time.time()
    with Pool(2) as pool:
        rows = pool.map(_one, todo, chunksize=1)
    cpu = sum(os.times()[2:4])
    hit = [r.get("verdict") == "unexplained" for r in rows]
    summary = {
        "ool_unexplained": f"{sum(hit)}/{len(hit)}",
        "rows": [
            {
                k: r.get(k)
                for k in ("name", "verdict", "winner", "nearest", "nominal_energy_ratio", "residual_ratio", "error")
            }
            for r in rows
        ],
        "wall_s": time.time() - t0,
        "cpu_s_children": cpu,
    }
    (OUT / "summary.json").write_text(json.dumps(summary, indent=2, default=float))
    print(json.dumps(summary, indent=1, default=float))
