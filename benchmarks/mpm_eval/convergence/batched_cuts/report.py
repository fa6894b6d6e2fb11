# SPDX-License-Identifier: Apache-2.0
"""The batched-cuts runs' tables and figure from ``runs/`` and ``sweep.jsonl`` (issue 9).

    python benchmarks/mpm_eval/convergence/batched_cuts/report.py   ->  report.md, fig_alive.png, fig_cost.png

Runs: the td student (``artifacts/gm_loco_student_td``), dry sand, 1.0 m/s, 10 s episodes, 5 ms frames, one rigid
substep; they differ in window, bed depth, voxel and rheology iterations (read from each run's summary.json).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/convergence/batched_cuts"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
# (label, runs pooled): the single-robot runs and the 8-robot run share one configuration
GROUPS = (
    ("A 3 cm / 250 it, window 1.8 x 1.0 m, bed 30 cm", ("td_r8_w1.8x1.0_d0.3", "td_r1_s0", "td_r1_s1", "td_r1_s2")),
    ("B 3 cm / 250 it, window 1.8 x 0.6 m, bed 30 cm", ("td_v03_r16_w18x06_d03",)),
    ("C 3 cm / 250 it, window 1.2 x 0.7 m, bed 20 cm", ("td_r32_w1.2x0.7_d0.2",)),
    ("D 3 cm / 150 it, window 1.8 x 0.6 m, bed 30 cm", ("td_v03_it150_r16_w18x06_d03",)),
    ("E 2 cm / 250 it, window 1.8 x 0.6 m, bed 30 cm", ("td_v02_r4_w18x06_d03",)),
)


def load(names: tuple[str, ...]) -> list[dict]:
    """Episode rows of the pooled runs."""
    return [json.loads(line) for n in names for line in (HERE / "runs" / n / "episodes.jsonl").read_text().splitlines()]


def _short(label: str) -> str:
    """'A 3 cm / 250 it, window 1.8 x 1.0 m, bed 30 cm' -> 'A 3 cm/250 it, 1.8x1.0 m, 30 cm'."""
    head, win, bed = label.split(", ")
    return f"{head.replace(' / ', '/')}, {win.removeprefix('window ').replace(' x ', 'x')}, {bed.removeprefix('bed ')}"


def main() -> None:
    """Write report.md and the two figures."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gmloco.eval.studies.convergence import compare_runs

    ref_rows = load(GROUPS[0][1])
    lines = ["| configuration | episodes | success | alive time median [s] (min-max) | mean sinkage [cm] | "
             "velocity error [m/s] | sole reached the floor | against A (`gmloco.eval.studies.convergence`) |",
             "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    fig, ax = plt.subplots(1, 2, figsize=(12, 3.8))
    for k, (label, names) in enumerate(GROUPS):
        rows = load(names)
        alive = np.array([r["alive_s"] for r in rows])
        sink = np.array([r["mean_sinkage"] for r in rows])
        v = None if k == 0 else compare_runs(ref_rows, rows)
        why = "" if v is None or not v.reasons else ": " + "; ".join(r.split(" (")[0] for r in v.reasons)
        p = (
            "-"
            if v is None
            else f"{v.decision} (time alive p = {v.alive_p:.2g}, sinkage {v.sinkage_rel_diff:+.0%}){why}"
        )
        lines.append(
            f"| {label} | {len(rows)} | {sum(r['success'] for r in rows)} | {np.median(alive):.1f} "
            f"({alive.min():.1f}-{alive.max():.1f}) | {100 * sink.mean():.1f} | "
            f"{np.mean([r['vel_error'] for r in rows]):.2f} | {sum(r['floor_reached'] for r in rows)} | {p} |"
        )
        jitter = np.random.default_rng(k).uniform(-0.15, 0.15, len(rows))
        ax[0].scatter(alive, k + jitter, s=14)
        ax[1].scatter(100 * sink, k + jitter, s=14)
    for a, name in zip(ax, ("time alive [s] (10 = walked the whole episode)", "mean sinkage of the lowest sole point [cm]"),
                       strict=True):  # fmt: skip
        a.set_yticks(range(len(GROUPS)), [_short(g[0]) for g in GROUPS])
        a.set_xlabel(name)
        a.invert_yaxis()
        a.grid(alpha=0.3)
    ax[0].set_title("td student on MPM dry sand, 1.0 m/s")
    ax[1].set_title("(A-E: see report.md)")
    fig.tight_layout()
    fig.savefig(HERE / "fig_alive.png", dpi=120)

    sweep = [json.loads(line) for line in (HERE / "sweep.jsonl").read_text().splitlines()]
    lines += ["", "| cost case | robots | window [m] | bed [m] | particles/voxel edge | iterations | particles | "
              "build [s] | frames/s | 10 s episodes/min (stepping only) |", "|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in sorted(sweep, key=lambda r: -r["frames_per_s"] * r["robots"]):
        lines.append(
            f"| {r['case']} | {r['robots']} | {r['window_length_m']:g} x {r['window_width_m']:g} (lead "
            f"{r['window_lead_m']:g}) | {r['bed_depth_m']:g} | {r['particles_per_voxel']} | {r['iterations']} | "
            f"{r['particles']:,} | {r['build_s']:.0f} | {r['frames_per_s']:.2f} | "
            f"{60 * r['robots'] * r['frames_per_s'] * r['frame_dt_s'] / 10.0:.2f} |"
        )
    fig, ax = plt.subplots(figsize=(6, 3.8))
    for r in sweep:
        cells = r["particles"] / r["particles_per_voxel"] ** 3 * r["iterations"] / 250
        ax.scatter(cells / 1e3, r["frames_per_s"], c="C1" if r["iterations"] != 250 else "C0", s=18)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("occupied voxels x iterations / 250 [thousands]")
    ax.set_ylabel("MPM frames per second (5 ms frames)")
    ax.set_title("H100, 3 cm voxels: cost follows voxels x iterations")
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(HERE / "fig_cost.png", dpi=120)
    (HERE / "report.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
