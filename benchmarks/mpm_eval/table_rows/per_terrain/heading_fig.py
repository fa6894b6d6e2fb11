# SPDX-License-Identifier: Apache-2.0
"""Why the soles left the sand window in the per-terrain runs' rows: the robot's turn or its reach (issue 9).

Reads every row's ``episodes.jsonl`` (each episode's largest sole reach from the pelvis, its yaw frame) and the
recordings (the first episode of every speed: the pelvis heading over time). An episode whose soles, over the
whole walk, never reached beyond the window's extent along the heading (less the 2 cm margin of
``gmloco.eval.g1.score.window_exit_cause``) and still left the window left it because the robot turned: the window is
a box of the grid's axes. Writes ``heading.json`` and ``fig_heading.png`` beside this script.

    python benchmarks/mpm_eval/table_rows/per_terrain/heading_fig.py
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np

from gmloco.deploy.logs.reader import read_log
from gmloco.eval.g1.score import WINDOW_EXIT_MARGIN_M
from gmloco.eval.metrics.locomotion import quat_wxyz_to_roll_pitch_yaw

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/table_rows/per_terrain"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
ROWS = {  # row folder -> (length, width, lead) of its window [m]
    "runs/table_td_basalt": (1.4, 0.6, 0.2),
    "runs/table_td_poppy_seed": (1.4, 0.6, 0.2),
    "runs/table_td_dry_sand_deep": (1.4, 0.6, 0.2),
    "runs/table_td_dry_sand_rough": (1.4, 0.6, 0.2),
    "runs/table_clr50_dry_sand_l1.4": (1.4, 0.6, 0.2),
    "runs/table_ppo_rigid_wide_dry_sand": (1.4, 1.3, 0.0),
    "../../convergence/grid_capacity_solvers/runs/table_td_dry_sand": (1.4, 0.6, 0.2),
}


def exit_causes(folder: Path, window: tuple[float, float, float]) -> dict[str, float]:
    """Early exits of a row, and how many of them had every reach of the walk within the window's extent."""
    length, width, lead = window
    eps = [json.loads(line) for line in (folder / "episodes.jsonl").read_text().splitlines() if line.strip()]
    early = [e for e in eps if e.get("window_exit_early")]
    m = WINDOW_EXIT_MARGIN_M
    within = [e for e in early
              if e["sole_behind_m"] + m <= 0.5 * length - lead and e["sole_ahead_m"] + m <= 0.5 * length + lead
              and e["sole_side_m"] + m <= 0.5 * width]  # fmt: skip
    alive = [e["alive_s"] for e in eps]
    if eps and "window_exit_s" not in eps[0]:  # runs before the window check (the grid-capacity runs): nothing to count
        return {
            "episodes": len(eps),
            "success": sum(e["success"] for e in eps),
            "early_exits": None,
            "exits_by_turn_for_sure": None,
            "median_alive_s": float(np.median(alive)),
            "median_exit_s": None,
        }
    return {"episodes": len(eps), "success": sum(e["success"] for e in eps), "early_exits": len(early),
            "exits_by_turn_for_sure": len(within), "median_alive_s": float(np.median(alive)) if alive else np.nan,
            "median_exit_s": float(np.median([e["window_exit_s"] for e in early])) if early else np.nan}  # fmt: skip


def headings(folder: Path) -> dict[str, np.ndarray]:
    """Pelvis heading [deg] over time (50 Hz) of each recording, relative to its start, by file stem."""
    out = {}
    for f in sorted((folder / "recordings").glob("*.mcap")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            q = np.asarray(read_log(f).channels["/odometry"].fields["orientation"], dtype=float)  # w x y z
        yaw = np.unwrap(quat_wxyz_to_roll_pitch_yaw(q)[:, 2])
        out[f.stem] = np.degrees(yaw - yaw[0])
    return out


def main() -> None:
    """Count the exits by cause per row, then write the json and the figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    report, traces = {}, {}
    for rel, window in ROWS.items():
        folder = (HERE / rel).resolve()
        if not (folder / "episodes.jsonl").exists():
            continue
        name = rel.split("/")[-1]
        hd = headings(folder)
        report[name] = exit_causes(folder, window) | {
            "window_m": {"length": window[0], "width": window[1], "lead": window[2]},
            "recorded_heading_turn_deg": {k: round(float(np.max(np.abs(v))), 1) for k, v in hd.items()},
        }
        traces[name] = hd
    (HERE / "heading.json").write_text(json.dumps(report, indent=1) + "\n")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    for ax, name in zip(axes, ("table_td_basalt", "table_td_dry_sand"), strict=True):
        for stem, deg in traces.get(name, {}).items():
            ax.plot(np.arange(len(deg)) * 0.02, deg, label=stem.split("__")[-1])
        ax.set(title=f"{name}: pelvis heading (first episode per speed)", xlabel="time [s]")
        ax.axhline(0.0, color="k", lw=0.5)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("heading turn from start [deg]")
    fig.tight_layout()
    fig.savefig(HERE / "fig_heading.png", dpi=120)
    for name, r in report.items():
        print(
            f"{name}: {r['early_exits']} (None: not recorded) / {r['episodes']} early exits, {r['exits_by_turn_for_sure']} with every reach "
            f"inside the window (turn); recorded turns {r['recorded_heading_turn_deg']}"
        )


if __name__ == "__main__":
    main()
