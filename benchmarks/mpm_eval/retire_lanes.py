# SPDX-License-Identifier: Apache-2.0
"""What retiring idle lanes buys, read from the runs' own records -> ``retire_lanes.{json,png}`` (issue 9).

A batch of 25 robots steps together until its last robot's episode ends; a fallen robot's lane is idle from then
on. Since the ablation-circle runs an idle lane's sand leaves the MPM solve (``G1EvalCfg.retire_idle_lanes``); before, it was
stepped to the end. ``gmloco.eval.studies.run_rates.running_rates`` splits each complete batch's wall time by how many
robots were still walking. This script pools those stretches, per setting (particles reserved) and per retire
setting, into bins of robots walking, and draws the solver rate [MPM frames/s] against them.

Caveat written on the figure: the ablation-circle runs to the transition-course runs records time a scene by ``sim_s``, the wall time inside its step,
which misses the frames in flight while ended episodes are scored (up to three frames per end). Bins where many
episodes end (10-24, 4-9) therefore read fast whichever the setting (19 ends within 44 frames took 1.9 s
by that clock in the transition-course runs' transition share 3 at ~2 frames/s); the 25-robot bin has no ends
and the 1-3 tail few; the grid check every 30 s also waits outside the step, so every bin reads ~8 % high at
4.42M particles. Runs from the transition-course runs' code on also record ``elapsed_s`` (the wall clock since the batch's first
frame), which ``running_rates`` uses instead; the square-window runs' code counts the waits as stepping time
(``G1MpmScene.sync``).

    python benchmarks/mpm_eval/retire_lanes.py
"""

from __future__ import annotations

import json
from pathlib import Path

from gmloco.eval.metrics.episodes import read_episodes
from gmloco.eval.studies.run_rates import retire_setting, running_rates

MPM_RESULTS = Path(__file__).resolve().parents[2] / "results" / "mpm_eval"  # the runs read, the outputs written
BINS = ((25, 25), (10, 24), (4, 9), (1, 3))
"""Robots walking (of 25 lanes), inclusive ranges."""
FOLDERS = (  # the row folders, oldest code first
    "table_rows/ablation_circles",
    "table_rows/transition_course",
    "table_rows/dry_sand_square_window",
    "table_rows/poppy_seed_deep_sand_reach",
    "table_rows/basalt_rough_square_window",
    "table_rows/last_rows_retire_lanes",
)
SERIES = (
    ("off", "step clock", "tab:gray"),
    ("on", "step clock", "tab:olive"),
    ("off", "wall clock", "tab:blue"),
    ("on", "wall clock", "tab:green"),
)
"""(retire setting, clock, colour) of the figure's bars, left to right."""


def pooled() -> dict[str, dict[str, dict[str, float]]]:
    """``{"<particles> particles, retire on|off, wall|step clock": {"lo-hi": {frames, seconds, frames_per_s, runs}}}``.

    Records with ``elapsed_s`` (the square-window runs on) are timed by the wall clock, older ones by the step clock; the two
    are pooled apart.
    """
    out: dict[str, dict[str, dict[str, float]]] = {}
    for folder in FOLDERS:
        for run in sorted((MPM_RESULTS / folder / "runs").iterdir()):
            path = run / "episodes.jsonl"
            if not path.is_file():
                continue
            eps = read_episodes(path)
            if not eps or eps[0].get("batch_size") != 25:
                continue  # a resumed batch has fewer lanes: not comparable
            clock = "wall clock" if "elapsed_s" in eps[0] else "step clock"
            retire = "on" if retire_setting(run) else "off"
            key = f"{eps[0]['particles'] / 1e6:.2f}M particles, retire {retire}, {clock}"
            for n, (frames, secs) in running_rates(eps).items():
                lo, hi = next(b for b in BINS if b[0] <= n <= b[1])
                cell = out.setdefault(key, {}).setdefault(f"{lo}-{hi}", {"frames": 0.0, "seconds": 0.0, "runs": []})
                cell["frames"] += frames
                cell["seconds"] += secs
                if f"{folder}/{run.name}" not in cell["runs"]:
                    cell["runs"].append(f"{folder}/{run.name}")
    for bins in out.values():
        for cell in bins.values():
            cell["frames_per_s"] = round(cell["frames"] / cell["seconds"], 3)
            cell["frames"], cell["seconds"] = round(cell["frames"]), round(cell["seconds"], 1)
    return dict(sorted(out.items()))


def figure(data: dict, path: Path) -> None:
    """Solver rate by robots walking, one panel per particle count, retire on vs off side by side."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sizes = sorted({k.split(",")[0] for k in data})
    fig, axes = plt.subplots(1, len(sizes), figsize=(5.2 * len(sizes), 4.0), squeeze=False)
    labels = [f"{lo}-{hi}" if lo != hi else f"{lo}" for lo, hi in BINS]
    for ax, size in zip(axes[0], sizes, strict=True):
        series = [(m, c, col) for m, c, col in SERIES if f"{size}, retire {m}, {c}" in data]
        width = 0.8 / max(len(series), 1)
        for j, (mode, clock, color) in enumerate(series):
            bins = data[f"{size}, retire {mode}, {clock}"]
            vals = [bins.get(f"{lo}-{hi}", {}).get("frames_per_s", 0.0) for lo, hi in BINS]
            xs = [i + (j - (len(series) - 1) / 2) * width for i in range(len(BINS))]
            label = f"idle lanes {'retired' if mode == 'on' else 'kept'} ({clock})"
            bars = ax.bar(xs, vals, width=width, color=color, label=label)
            for b, v, (lo, hi) in zip(bars, vals, BINS, strict=True):
                secs = bins.get(f"{lo}-{hi}", {}).get("seconds")
                if v:
                    ax.text(
                        b.get_x() + b.get_width() / 2, v, f"{v:.1f}\n{secs:.0f} s", ha="center", va="bottom", fontsize=7
                    )
        ax.set_xticks(range(len(BINS)), labels)
        ax.set_xlabel("robots still walking (of 25 lanes)")
        ax.set_ylabel("MPM frames per second (all lanes step together)")
        ax.set_title(size)
        ax.set_ylim(0, 1.5 * max(c["frames_per_s"] for k, b in data.items() if k.startswith(size) for c in b.values()))
        ax.legend(loc="upper left", fontsize=7, ncol=2)
    fig.suptitle("Retiring idle lanes (issue 9; H200, 3 cm, 500 sweeps; labels: rate, wall seconds pooled)\n"
                 "step clock (the ablation-circle runs to the transition-course runs) missed the frames in flight at each grid check (every 30 s, every "
                 "episode end): it reads high, most where episodes end; wall clock (the square-window runs on) does not; "
                 "1.88M wall clock: the last-row runs' 10 s A/B, side by side",
                 fontsize=9)  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main() -> None:
    """Write ``retire_lanes.json`` and ``fig_retire_lanes.png`` beside this script and print the pooled rates."""
    data = pooled()
    (MPM_RESULTS / "retire_lanes.json").write_text(json.dumps(data, indent=1) + "\n")
    figure(data, MPM_RESULTS / "fig_retire_lanes.png")
    for key, bins in data.items():
        print(key, {b: c["frames_per_s"] for b, c in bins.items()})


if __name__ == "__main__":
    main()
