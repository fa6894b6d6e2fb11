# SPDX-License-Identifier: Apache-2.0
"""Tuning episodes of the sand suite's composite motion (tuning seeds, not a test).

Runs the named sand episodes one after the other (one process) with the sweep's own ``run_episode``, each with
the motion(s) given, on the tuning seeds below, and writes rows and keys under ``OUT/<motion>/``. Existing rows
are kept (resume).

Usage (from the repository root)::

    uv run python benchmarks/mismatch_benchmark/composite_tuning/run_tuning.py \
        --episodes imu.gyro_bias,imu.misalignment,terrain.depth_hardening,none --motions composite,walk
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from gmloco.deploy.mismatch.benchmark.episodes import sand_episode_list
from gmloco.deploy.mismatch.benchmark.policy_motion import MOTIONS
from gmloco.deploy.mismatch.benchmark.sweep import _star, source_sha256

RESULTS_HOME = Path(__file__).resolve().parents[3] / "results/mismatch_benchmark/composite_tuning"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

EFFECT_SEED = 500
"""Tuning seed of every effect episode (the suite's seed index 0; v3 used 12000, the stock suite 2000)."""
NULL_SEED = 550
"""Tuning seed of the null episode (v3 used 13000+, the stock suite 3000+)."""


def main() -> None:
    """Run the episodes and print one line per row."""
    p = argparse.ArgumentParser()
    p.add_argument("--episodes", required=True, help="comma-separated effect ids ('none' for a null)")
    p.add_argument("--motions", default="composite,walk")
    p.add_argument("--out", type=Path, default=RESULTS_HOME)
    p.add_argument(
        "--params",
        default=None,
        help="JSON parameters replacing the suite's mid strength (one effect); rows go to OUT/<motion>_<tag>/",
    )
    p.add_argument("--tag", default=None, help="folder suffix for --params runs")
    p.add_argument(
        "--seed-index", type=int, default=0, help="k: seeds EFFECT_SEED + k and NULL_SEED + k (names end -k)"
    )
    a = p.parse_args()
    for eid in a.episodes.split(","):
        for motion in a.motions.split(","):
            eps = sand_episode_list(1, 1, motion=motion)
            ep = next(e for e in eps if e["effect"] == eid)
            k = a.seed_index
            name = ep["name"].rsplit("-", 1)[0] + f"-{k}"
            ep = {**ep, "name": name, "seed": (NULL_SEED if eid == "none" else EFFECT_SEED) + k}
            out = a.out / motion
            if a.params is not None:
                if a.tag is None:
                    raise SystemExit("--params needs --tag")
                ep["params"] = json.loads(a.params)
                out = a.out / f"{motion}_{a.tag}"
            if (out / "rows" / f"{ep['name']}.json").exists():
                continue
            t0 = time.time()
            row = _star((ep, str(out), MOTIONS[motion], None, None, None))
            row["source_sha256"] = source_sha256()
            f = out / "rows" / f"{ep['name']}.json"
            if f.exists():  # add provenance to the sweep's row
                f.write_text(json.dumps(row, default=float))
            e = row.get("energy", {})
            gain = 1 - e["oracle"] / e["nominal"] if e else None
            print(
                json.dumps(
                    {
                        "name": ep["name"],
                        "seed": ep["seed"],
                        "verdict": row.get("verdict"),
                        "winner": row.get("winner"),
                        "oracle_gain": gain,
                        "error": row.get("error"),
                        "wall_s": time.time() - t0,
                    }
                ),
                flush=True,
            )


if __name__ == "__main__":
    main()
