# SPDX-License-Identifier: Apache-2.0
"""What the sand window did to the td student's dry-sand row -> ``window_effect.{json,png}`` (issue 9).

The same policy on the same sand, scored twice: the ablation-circle runs at the tables' 1.4 x 0.6 m window (it does not turn with
the robot, so walks whose heading drifts step out of its side) and the square-window runs at the square 1.4 x 1.4 m window
(which holds the tables' reach at any heading). Per speed: success with its 95 % Wilson interval, and how the
walks that left the window early ended. Fisher's exact test compares the two windows per speed and over
1.0-1.5 m/s (above, both score 0).

    python benchmarks/mpm_eval/window_effect.py
"""

from __future__ import annotations

import json
from pathlib import Path

from scipy.stats import fisher_exact

from gmloco.eval.metrics.episodes import read_episodes, wilson_interval

MPM_RESULTS = Path(__file__).resolve().parents[2] / "results" / "mpm_eval"  # the runs read, the outputs written
ROWS = {
    "tables' 1.4 x 0.6 m window (the ablation-circle runs)": "table_rows/ablation_circles/runs/table_td_dry_sand_x4_share*",
    "square 1.4 x 1.4 m window (the square-window runs)": "table_rows/dry_sand_square_window/runs/table_td_dry_sand_sq_share*",
}
SPEEDS = (1.0, 1.5, 2.0, 2.5)


def per_speed(pattern: str) -> dict[str, dict[str, float]]:
    """``{speed: {episodes, successes, success_pct, lo95, hi95, early_exits, early_exit_successes, turn_exits}}``."""
    eps = [e for run in sorted(MPM_RESULTS.glob(pattern)) for e in read_episodes(run / "episodes.jsonl")]
    out = {}
    for v in SPEEDS:
        rows = [e for e in eps if abs(e["speed"] - v) < 1e-6]
        n, k = len(rows), sum(bool(e["success"]) for e in rows)
        early = [e for e in rows if e.get("window_exit_early")]
        lo, hi = wilson_interval(k, n)
        out[f"{v}"] = {"episodes": n, "successes": k, "success_pct": round(100 * k / max(n, 1), 1),
                       "lo95_pct": round(100 * lo, 1), "hi95_pct": round(100 * hi, 1), "early_exits": len(early),
                       "early_exit_successes": sum(bool(e["success"]) for e in early),
                       "turn_exits": sum(e.get("window_exit_cause") == "turn" for e in early)}  # fmt: skip
    return out


def compare(data: dict[str, dict[str, dict[str, float]]]) -> dict[str, float]:
    """Fisher's exact p (two-sided) between the windows per speed and pooled over 1.0-1.5 m/s."""
    a, b = data.values()

    def p(keys: tuple[str, ...]) -> float:
        table = [[sum(d[s]["successes"] for s in keys), sum(d[s]["episodes"] - d[s]["successes"] for s in keys)]
                 for d in (a, b)]  # fmt: skip
        return round(float(fisher_exact(table)[1]), 3)

    return {**{f"p_{s}": p((s,)) for s in ("1.0", "1.5")}, "p_1.0-1.5": p(("1.0", "1.5"))}


def figure(data: dict[str, dict[str, dict[str, float]]], path: Path) -> None:
    """Success by speed at each window (Wilson 95 % bars); early window exits and their outcome annotated."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.2, 4.2))
    width = 0.38
    for j, ((label, rows), color) in enumerate(zip(data.items(), ("tab:gray", "tab:green"), strict=True)):
        xs = [i + (j - 0.5) * width for i in range(len(SPEEDS))]
        vals = [rows[f"{v}"]["success_pct"] for v in SPEEDS]
        err = [[vals[i] - rows[f"{v}"]["lo95_pct"] for i, v in enumerate(SPEEDS)],
               [rows[f"{v}"]["hi95_pct"] - vals[i] for i, v in enumerate(SPEEDS)]]  # fmt: skip
        ax.bar(xs, vals, width=width, color=color, yerr=err, capsize=3, label=label)
        for x, v in zip(xs, SPEEDS, strict=True):
            r = rows[f"{v}"]
            text = f"{r['successes']}/{r['episodes']}\nexits {r['early_exits']}"
            if r["turn_exits"]:
                text += f"\n({r['turn_exits']} turn)"
            ax.text(x, r["hi95_pct"] + 1.5, text, ha="center", va="bottom", fontsize=7)
    ax.set_xticks(range(len(SPEEDS)), [f"{v} m/s" for v in SPEEDS])
    ax.set_ylabel("success [%] (95 % Wilson interval)")
    ax.set_ylim(0, 110)
    ax.legend(fontsize=8, loc="upper right", bbox_to_anchor=(1.0, 0.78))
    ax.set_title("td student on MPM dry sand: the window's turn exits cost successes\n"
                 "(exits: soles left the window > 0.25 s before the end; turn: the robot turned out of it)",
                 fontsize=9)  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main() -> None:
    """Write ``window_effect.json`` and ``fig_window_effect.png`` beside this script and print the comparison."""
    data = {label: per_speed(pattern) for label, pattern in ROWS.items()}
    doc = {"rows": ROWS, "per_speed": data, "fisher": compare(data)}
    (MPM_RESULTS / "window_effect.json").write_text(json.dumps(doc, indent=1) + "\n")
    figure(data, MPM_RESULTS / "fig_window_effect.png")
    for label, rows in data.items():
        print(label, {v: f"{r['successes']}/{r['episodes']}" for v, r in rows.items()})
    print(doc["fisher"])


if __name__ == "__main__":
    main()
