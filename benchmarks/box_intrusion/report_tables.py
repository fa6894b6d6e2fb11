# SPDX-License-Identifier: Apache-2.0
"""Print the README tables of a box-study directory (scores vs MPM, absolute sinkage error, MPM rebounds).

Usage: ``uv run python benchmarks/box_intrusion/report_tables.py [DIR ...]`` (CPU, seconds; default
``results/box_intrusion/box_v0.03_i1000``). Reads ``summary.json``, ``trials.csv`` and the series (``grf.jsonl[.gz]``) as written
by ``workflows/box_study.py``; runs nothing.

Printed per variant and model: the summary's medians (travel and sinkage relative errors, GRF profile error / mg,
travel, sinkage), the median absolute sinkage error [mm] over matched trials (the relative sinkage error divides
by max(|sinkage_mpm|, 5 mm), which is near the floor once MPM sinkage is ~1 cm), and for MPM the number of
trials whose box rebounds: final position along the launch direction more than 2 cm behind its furthest point.
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np

from gmloco.eval.studies.study_io import StudyRecords

REBOUND = 0.02
"""Backward travel from the furthest point that counts as a rebound [m]."""


def load_rows(d: Path) -> dict[tuple[str, str], dict[int, dict[str, float]]]:
    """Trials by (variant, model) and trial index."""
    out: dict[tuple[str, str], dict[int, dict[str, float]]] = {}
    with (d / "trials.csv").open() as f:
        for r in csv.DictReader(f):
            out.setdefault((r["variant"], r["model"]), {})[int(r["trial"])] = {
                "travel": float(r["travel"]), "sinkage": float(r["sinkage"])}  # fmt: skip
    return out


def rebounds(d: Path) -> dict[str, tuple[int, int]]:
    """Per variant: (MPM trials that rebound, MPM trials)."""
    out: dict[str, list[int]] = {}
    for r in StudyRecords(d).series():
        if r["model"] != "mpm":
            continue
        x = np.asarray(r["pos"])[:, 0]
        out.setdefault(r["variant"], []).append(int(x.max() - x[-1] > REBOUND))
    return {v: (sum(n), len(n)) for v, n in out.items()}


def report(d: Path) -> None:
    """Print the tables of one study directory."""
    summary = json.loads((d / "summary.json").read_text())
    rows = load_rows(d)
    reb = rebounds(d)
    print(f"== {d}")
    for variant, var in summary["variants"].items():
        mpm = rows.get((variant, "mpm"), {})
        n_reb, n = reb.get(variant, (0, 0))
        print(f"-- {variant}: MPM {var['mpm_trials_done']} trials, travel {var['mpm_travel_median']:.3f} m, "
              f"sinkage {1e3 * var['mpm_sinkage_median']:.1f} mm, rebounds {n_reb}/{n}; best {var['best']}")  # fmt: skip
        print("model | travel err | sinkage rel err | GRF err/mg | travel m | sinkage mm | abs sinkage err mm")
        for model, s in var["scores"].items():
            if not s.get("matched_trials"):
                continue
            mine = rows[(variant, model)]
            shared = sorted(set(mine) & set(mpm))
            abs_err = np.median([abs(mine[t]["sinkage"] - mpm[t]["sinkage"]) for t in shared])
            print(f"{model} | {s['travel_rel_err_median']:.2f} | {s['sinkage_rel_err_median']:.2f} | "
                  f"{s['grf_profile_err_median']:.2f} | {s['travel_median']:.3f} | {1e3 * s['sinkage_median']:.0f} | "
                  f"{1e3 * abs_err:.0f}")  # fmt: skip
    for variant, lat in summary.get("lateral_impact", {}).items():
        print(f"-- lateral impact, {variant}: best {lat['best']}")
        for model, m in lat["models"].items():
            errs = ""
            if "peak_lateral_err_median" in m:
                errs = f" | {m['peak_lateral_err_median']:.2f} | {m['impulse_rel_err_median']:.2f}"
            print(f"{model} | {m['peak_lateral_over_mg_median']:.3f} | {m['lateral_impulse_abs_median']:.2f}{errs}")


def main() -> None:
    """Report every directory given (default: the main study)."""
    dirs = sys.argv[1:] or ["results/box_intrusion/box_v0.03_i1000"]
    for d in dirs:
        report(Path(d))


if __name__ == "__main__":
    main()
