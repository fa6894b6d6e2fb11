# SPDX-License-Identifier: Apache-2.0
"""Basalt at the square window (the basalt and rough-sand runs, issue 9): does the heading's drift decide which walks finish?

Every one of the 100 walks stayed upright for the 10 s, so a walk fails only by not finishing the straight course
(progress along the commanded line short of 80 % of v x 10 s). Plots each walk's largest heading turn from its
start (``heading_turn_deg``) by speed, finished or not, with a Mann-Whitney test per speed and over all. Writes
``heading_outcome.json`` and ``fig_heading_outcome.png`` beside this script.

    python benchmarks/mpm_eval/table_rows/basalt_rough_square_window/heading_outcome.py
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy.stats import mannwhitneyu

from gmloco.eval.metrics.episodes import read_episodes

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/table_rows/basalt_rough_square_window"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME


def walks() -> list[dict]:
    """The basalt row's episodes (four shares, one speed each)."""
    rows: list[dict] = []
    for path in sorted((HERE / "runs").glob("table_td_basalt_sq_share*of4/episodes.jsonl")):
        rows += read_episodes(path)
    return rows


def _split(rows: list[dict]) -> tuple[list[float], list[float]]:
    done = [abs(r["heading_turn_deg"]) for r in rows if r["success"]]
    not_done = [abs(r["heading_turn_deg"]) for r in rows if not r["success"]]
    return done, not_done


def summary(rows: list[dict]) -> dict:
    """Median turns of finished and unfinished walks, and the test between them, per speed and over all."""
    out: dict[str, dict] = {}
    speeds = sorted({float(r["speed"]) for r in rows})
    for key, group in [(f"{v:g} m/s", [r for r in rows if float(r["speed"]) == v]) for v in speeds] + [("all", rows)]:
        done, not_done = _split(group)
        out[key] = {
            "episodes": len(group),
            "finished": len(done),
            "upright_10s": sum(r["alive_s"] >= 10.0 - 1e-6 for r in group),
            "turn_median_finished_deg": round(float(np.median(done)), 1) if done else None,
            "turn_median_unfinished_deg": round(float(np.median(not_done)), 1) if not_done else None,
            "mann_whitney_p": float(f"{mannwhitneyu(done, not_done).pvalue:.2g}") if done and not_done else None,
        }
    return out


def main() -> None:
    """Write the JSON and the figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = walks()
    doc = {"source": "runs/table_td_basalt_sq_share{0..3}of4", "by_speed": summary(rows)}
    (HERE / "heading_outcome.json").write_text(json.dumps(doc, indent=1) + "\n")
    rng = np.random.default_rng(0)
    fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
    for k, v in enumerate(sorted({float(r["speed"]) for r in rows})):
        group = [r for r in rows if float(r["speed"]) == v]
        for ok, colour, dx in ((True, "C2", -0.12), (False, "C3", 0.12)):
            turns = [abs(r["heading_turn_deg"]) for r in group if bool(r["success"]) == ok]
            x = k + dx + rng.uniform(-0.06, 0.06, len(turns))
            label = ("finished" if ok else "upright, course not finished") if k == 0 else None
            ax.scatter(x, turns, s=14, color=colour, alpha=0.8, label=label)
            if turns:
                ax.hlines(np.median(turns), k + dx - 0.1, k + dx + 0.1, color="k", lw=1.5)
    speeds = sorted({float(r["speed"]) for r in rows})
    ax.set_xticks(range(len(speeds)), [f"{v:g} m/s\n{doc['by_speed'][f'{v:g} m/s']['finished']} of 25" for v in speeds])
    ax.set_ylabel("largest heading turn in 10 s [deg]")
    p = doc["by_speed"]["all"]["mann_whitney_p"]
    ax.set_title(f"td student, MPM basalt, square window: all 100 upright; finished vs not p = {p:g}", fontsize=9)
    ax.legend(fontsize=8, loc="upper left")
    fig.savefig(HERE / "fig_heading_outcome.png", dpi=120)
    plt.close(fig)
    print(json.dumps(doc["by_speed"]["all"]))


if __name__ == "__main__":
    main()
