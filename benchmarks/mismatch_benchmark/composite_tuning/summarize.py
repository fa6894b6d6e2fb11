# SPDX-License-Identifier: Apache-2.0
"""Collect the tuning rows under this folder into ``summary.json`` (one entry per row; tuning seeds, not a test).

Usage: ``uv run python benchmarks/mismatch_benchmark/composite_tuning/summarize.py``
"""

from __future__ import annotations

import json
from pathlib import Path

RESULTS_HOME = Path(__file__).resolve().parents[3] / "results/mismatch_benchmark/composite_tuning"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME


def main() -> None:
    """Write ``summary.json`` and print it."""
    out = []
    for f in sorted(HERE.glob("*/rows/*.json")):
        r = json.loads(f.read_text())
        e = r.get("energy")
        truth = r["effect"]
        c = {h["id"]: h for h in r.get("confirmed", [])}.get(truth, {})
        out.append(
            {
                "folder": f.parent.parent.name,
                "name": r["name"],
                "motion": r.get("motion"),
                "seed": r["seed"],
                "params": r["params"],
                "verdict": r.get("verdict"),
                "winner": r.get("winner"),
                "correct": r.get("winner") == truth if truth != "none" else r.get("verdict") == "no_mismatch",
                "truth_rank": r["ranked"].index(truth) + 1 if truth in r.get("ranked", []) else None,
                "oracle_gain": None if not e else 1.0 - e["oracle"] / e["nominal"],
                "nominal_energy_ratio": r.get("nominal_energy_ratio"),
                "residual_ratio": r.get("residual_ratio"),
                "truth_fitted": {k: c.get(k) for k in ("passed", "dbic", "heldout_gain", "heldout_gain_lo_signals")}
                if c
                else None,
                "fit": r.get("fit"),
                "runtime_s": r.get("runtime_s"),
                "error": r.get("error"),
            }
        )
    (HERE / "summary.json").write_text(json.dumps({"tuning_seeds_not_a_test": True, "rows": out}, indent=1))
    for o in out:
        print(o["folder"], o["name"], o["verdict"], o["winner"], o["oracle_gain"], o["truth_fitted"])


if __name__ == "__main__":
    main()
