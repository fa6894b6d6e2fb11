# SPDX-License-Identifier: Apache-2.0
"""Iterations the rheology solve needs per frame of a G1 walk, per solver: ``residuals_*.jsonl`` -> table + figure.

    python benchmarks/mpm_eval/convergence/rheology_iterations_cpu/residual_report.py   ->  residual_report.md, fig_residuals.png

A frame converges when both the l2 and the linf residual (relative to Newton's tolerance scale) are below the
tolerance; Newton checks every 25 Gauss-Seidel sweeps. Frames that have not converged at the cap count as the cap
in the mean (so the mean is a lower bound) and are reported separately.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/convergence/rheology_iterations_cpu"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME


def frame_stats(row: dict) -> tuple[float | None, float, float]:
    """(Gauss-Seidel iterations to tolerance or None, linf residual at 250 iterations, at the end)."""
    tol, trace = row["tol"], row["trace"]
    done = [it for it, l2, linf in trace if l2 < tol and linf < tol]
    at250 = [linf for it, _, linf in trace if it == 250]
    end = trace[-1][2] if trace else float("nan")
    return (done[0] if done else None), (at250[0] if at250 else end), end


def main() -> None:
    """Write the table and the figure for every residuals_*.jsonl here."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lines = ["| solver | frames | converged within the cap | GS iterations to tolerance: median / p90 / mean (cap "
             "counted) | Krylov warm-start iterations (mean) | linf residual at 250 GS iterations: median / max "
             "[x tolerance] | CPU s per frame (mean) |", "|---|---|---|---|---|---|---|"]  # fmt: skip
    fig, ax = plt.subplots(1, 2, figsize=(11, 3.8))
    for k, path in enumerate(sorted(HERE.glob("residuals_*.jsonl"))):
        rows = [json.loads(line) for line in path.read_text().splitlines()]
        rows = [r for r in rows if r["frame"] >= 5]  # the drop: no contact yet
        cap, tol = rows[0]["iters_max"], rows[0]["tol"]
        stats = [frame_stats(r) for r in rows]
        its = np.array([s[0] if s[0] is not None else cap for s in stats], dtype=float)
        conv = np.array([s[0] is not None for s in stats])
        at250 = np.array([s[1] for s in stats]) / tol
        lin = [sum(n for _, n, _ in r["linear"]) for r in rows]
        name = rows[0]["solver"]
        ci = its[conv]
        lines.append(
            f"| {name} | {len(rows)} | {conv.mean():.0%} | {np.median(ci):.0f} / {np.percentile(ci, 90):.0f} / "
            f"{its.mean():.0f} | {np.mean(lin):.0f} | {np.median(at250):.1f} / {at250.max():.1f} | "
            f"{np.mean([r['wall_s'] for r in rows]):.2f} |"
        )
        frames = np.array([r["frame"] for r in rows])
        ax[0].plot(frames * 5.0, its, ".", ms=4, label=name, color=f"C{k}")
        ax[1].hist(its, bins=np.arange(0, cap + 50, 50), histtype="step", label=name, color=f"C{k}")
    ax[0].axhline(250, color="k", lw=0.8, ls="--")
    ax[0].set_xlabel("time [ms] (G1 walking at 1.0 m/s, 5 cm voxels)")
    ax[0].set_ylabel("Gauss-Seidel iterations to tolerance")
    ax[0].set_title(f"cap {cap}: points on the cap did not converge")
    ax[1].set_xlabel("Gauss-Seidel iterations to tolerance")
    ax[1].set_ylabel("frames")
    ax[1].axvline(250, color="k", lw=0.8, ls="--")
    for a in ax:
        a.grid(alpha=0.3)
        a.legend()
    fig.tight_layout()
    fig.savefig(HERE / "fig_residuals.png", dpi=120)
    (HERE / "residual_report.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
