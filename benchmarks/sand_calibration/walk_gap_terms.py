# SPDX-License-Identifier: Apache-2.0
"""Which fitted sand term makes the calibrated training sand miss the MPM walks: one term changed at a time.

Reads the training-gate summaries of ``results/sand_calibration/walk_gap_terms/gate_<variant>.json`` (the td
student on the 30 cm calibrated bed, dry sand, 1.0 and 1.5 m/s, each variant's fitted-term file under
``extensions/``) and the MPM walks of the same policy and cells
(``results/sand_calibration/predicted/predicted_vs_mpm_success.json``); writes ``summary.json`` and
``fig_walk_gap_terms.png`` there::

    uv run python benchmarks/sand_calibration/walk_gap_terms.py
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

RESULTS_HOME = Path("results/sand_calibration/walk_gap_terms")
"""This study's results folder."""
PREDICTION = Path("results/sand_calibration/predicted/predicted_vs_mpm_success.json")
"""The prediction test's file, which holds the MPM walks of the td student per cell."""
MPM_TABLES = Path("results/mpm_eval/tables/tables.json")
"""The MPM tables, whose straight dry-sand row of the policy (1.0-2.5 m/s pooled) gives its mean stance depth."""
POLICY = "gm_loco_student_td"
MATERIAL = "dry_sand"
SPEEDS = ("1", "1.5")
"""Speed keys [m/s] as the gate and the prediction write them."""
METRICS = ("success_course_pct", "success_pct", "vel_error_mps", "stance_sink_cm", "stance_sink_peak_cm")
"""Gate keys reported per cell (success by MPM's course rule, survival, velocity error, stance depth mean / peak)."""


def _variants() -> list[str]:
    """Variant names in the order of the extension files' ``order`` field (fitted first)."""
    names = [p.stem.removeprefix("gate_") for p in RESULTS_HOME.glob("gate_*.json")]
    order = {n: json.loads((RESULTS_HOME / "extensions" / f"{n}.json").read_text()).get("order", 99) for n in names}
    return sorted(names, key=lambda n: (order[n], n))


def _atomic_write(path: Path, text: str) -> None:
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def main() -> None:
    """Collect the cells, write the summary and the figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mpm_cells = json.loads(PREDICTION.read_text())["predicted_vs_mpm_success"][POLICY][MATERIAL]
    mpm = {s: mpm_cells[s]["mpm_walk"] for s in SPEEDS}
    table_rows = json.loads(MPM_TABLES.read_text())["rows"]
    row = next(r for r in table_rows if (r["policy"], r["terrain"], r["scenario"]) == (POLICY, MATERIAL, "straight"))
    mpm_sink_cm = float(row["mean_sinkage_cm"])
    rows: dict[str, dict] = {}
    for name in _variants():
        gate = json.loads((RESULTS_HOME / f"gate_{name}.json").read_text())
        ext = json.loads((RESULTS_HOME / "extensions" / f"{name}.json").read_text())
        rows[name] = {
            "changed": ext.get("changed", {}),
            "episodes_per_cell": gate["setup"]["episodes_per_cell"],
            **{k: gate[k][MATERIAL] for k in METRICS},
            "failures": gate["failures"][MATERIAL],
        }
    summary = {
        "policy": POLICY,
        "material": MATERIAL,
        "speeds_mps": SPEEDS,
        "mpm_walk": mpm,
        "mpm_mean_sinkage_cm_straight_1_to_2_5_mps": mpm_sink_cm,
        "variants": rows,
    }
    _atomic_write(RESULTS_HOME / "summary.json", json.dumps(summary, indent=1) + "\n")

    names = list(rows)
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), constrained_layout=True)
    width = 0.8 / len(SPEEDS)
    panels = (
        ("success by MPM's course rule [%]", "success_course_pct", "success_pct"),
        ("velocity error [m/s]", "vel_error_mps", "vel_error_mps"),
        ("stance depth, mean [cm]", "stance_sink_cm", None),
    )
    for ax, (label, key, mpm_key) in zip(axes, panels, strict=True):
        for j, speed in enumerate(SPEEDS):
            vals = [rows[n][key].get(speed) for n in names]
            xs = [i + (j - (len(SPEEDS) - 1) / 2) * width for i in range(len(names))]
            ax.bar(xs, [math.nan if v is None else v for v in vals], width, label=f"gate {speed} m/s")
            if mpm_key is not None and mpm[speed].get(mpm_key) is not None:
                ax.axhline(mpm[speed][mpm_key], ls="--", lw=1, color=f"C{j}", label=f"MPM {speed} m/s")
        if key == "stance_sink_cm":
            ax.axhline(mpm_sink_cm, ls=":", lw=1, color="k", label="MPM, 1.0-2.5 m/s pooled")
            ax.legend(fontsize=7)
        ax.set_xticks(range(len(names)), names, rotation=20, ha="right", fontsize=8)
        ax.set_ylabel(label)
        ax.grid(axis="y", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle(f"{POLICY} on the 30 cm calibrated dry-sand bed: the fitted terms varied, and refits", fontsize=10)
    tmp = RESULTS_HOME / "fig_walk_gap_terms.tmp.png"
    fig.savefig(tmp, dpi=120)
    os.replace(tmp, RESULTS_HOME / "fig_walk_gap_terms.png")
    print(f"{RESULTS_HOME}/summary.json, fig_walk_gap_terms.png: {len(names)} variants")


if __name__ == "__main__":
    main()
