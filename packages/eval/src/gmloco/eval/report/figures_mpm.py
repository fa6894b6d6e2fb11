# SPDX-License-Identifier: Apache-2.0
"""Figures of the MPM evaluation: success and velocity error vs commanded speed; the transition course per medium."""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["fig_mpm_speed_sweep", "fig_mpm_transition", "fig_per_terrain", "fig_policies_by_speed", "write_figures"]


def _by_speed(rs: list[dict[str, Any]], key: str) -> tuple[np.ndarray, np.ndarray]:
    """(speeds, mean metric per speed) over finite values."""
    speeds = np.array(sorted({float(r["speed"]) for r in rs}))
    vals = []
    for v in speeds:
        xs = [float(r[key]) for r in rs if r["speed"] == v and r.get(key) is not None and math.isfinite(float(r[key]))]
        vals.append(np.mean(xs) if xs else np.nan)
    return speeds, np.array(vals)


def _success_with_interval(groups: list[list[dict[str, Any]]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per group of episodes: (count, success rate [%] (NaN for none), [G, 2] 95 % Wilson interval [%])."""
    from gmloco.eval.metrics.episodes import wilson_interval

    n = np.array([len(g) for g in groups])
    wins = np.array([sum(bool(r["success"]) for r in g) for g in groups])
    rate = np.where(n > 0, 100.0 * wins / np.maximum(n, 1), np.nan)
    ci = np.array([wilson_interval(int(w), int(m)) for w, m in zip(wins, n, strict=True)]).reshape(-1, 2) * 100.0
    return n, rate, ci


def fig_mpm_speed_sweep(rows: list[dict[str, Any]], path: str | Path, policy: str) -> Path:
    """Success rate [%] and velocity tracking error [m/s] vs commanded speed, one line per (terrain, scenario)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cells: dict[str, list[dict[str, Any]]] = {}
    for r in rows:
        cells.setdefault(f"{r['terrain']} / {r['scenario']}", []).append(r)
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(9, 3.4), constrained_layout=True)
    for name, rs in cells.items():
        v, s = _by_speed(rs, "success")
        ax0.plot(v, 100.0 * s, "o-", label=name)
        v, e = _by_speed(rs, "vel_error")
        ax1.plot(v, e, "o-", label=name)
    ax0.set(xlabel="commanded speed [m/s]", ylabel="success rate [%]", ylim=(-5, 105))
    ax1.set(xlabel="commanded speed [m/s]", ylabel="velocity tracking error [m/s]")
    ax0.legend(fontsize=7)
    fig.suptitle(f"{policy} on MPM sand ({len(rows)} episodes)", fontsize=9)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def fig_mpm_transition(rows: list[dict[str, Any]], path: str | Path, policy: str) -> Path:
    """The transition course per medium, in walking order: decoded stiffness eta [-], swing apex and lift [cm].

    One line per commanded speed [m/s] and the mean over all episodes (black, ``tables_mpm.table_transition``);
    a point is the mean over the episodes that stepped on that medium, labelled with their count.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gmloco.eval.report.tables_mpm import table_transition

    layered = [r for r in rows if r.get("layers")]
    table = table_transition(layered)
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), constrained_layout=True)
    columns = ((3, "decoded stiffness eta [-]"), (4, "swing apex above the surface [cm]"), (5, "swing lift [cm]"))
    speeds = sorted({float(r["speed"]) for r in layered if "speed" in r})
    for scenario in dict.fromkeys(r[0] for r in table):
        media = [r[1] for r in table if r[0] == scenario]
        for v in speeds:
            cells = {r[1]: r for r in table_transition([r for r in layered if float(r.get("speed", -1)) == v])
                     if r[0] == scenario}  # fmt: skip
            xs = [m for m in media if m in cells]
            for ax, (col, _) in zip(axes, columns, strict=True):
                ax.plot(xs, [cells[m][col] for m in xs], "o-", alpha=0.6, label=f"{v:g} m/s")
        cells = [r for r in table if r[0] == scenario]
        for ax, (col, label) in zip(axes, columns, strict=True):
            ax.plot(media, [r[col] for r in cells], "ks-", lw=2, label=f"all ({scenario})")
            for r in cells:
                ax.annotate(f"n={r[2]}", (r[1], r[col]), textcoords="offset points", xytext=(4, 4), fontsize=7)
            ax.set(ylabel=label)
    axes[0].legend(fontsize=7)
    fig.suptitle(f"{policy} on the MPM transition course (media in walking order; {len(layered)} episodes)", fontsize=9)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def fig_policies_by_speed(runs: list[tuple[str, list[dict[str, Any]]]], path: str | Path, cell: str) -> Path:
    """Policies side by side on one (terrain, scenario) cell against the commanded speed [m/s].

    Left: success rate [%] with its 95 % Wilson interval; right: median time alive [s].
    ``runs``: (policy label, that cell's episodes).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(9, 3.4), constrained_layout=True)
    for k, (label, rs) in enumerate(runs):
        speeds = sorted({float(r["speed"]) for r in rs})
        at = [[r for r in rs if float(r["speed"]) == v] for v in speeds]
        _, rate, lo_hi = _success_with_interval(at)
        x = np.array(speeds) + 0.02 * (k - 0.5 * (len(runs) - 1))  # a small dodge so the intervals stay apart
        err = np.vstack([rate - lo_hi[:, 0], lo_hi[:, 1] - rate])
        ax0.errorbar(x, rate, yerr=err, fmt="o-", capsize=3, label=f"{label} ({len(rs)} ep.)")
        ax1.plot(x, [float(np.median([r["alive_s"] for r in g])) for g in at], "o-", label=label)
    ax0.set(xlabel="commanded speed [m/s]", ylabel="success rate [%] (95 % interval)", ylim=(-5, 105))
    ax1.set(xlabel="commanded speed [m/s]", ylabel="median time alive [s]", ylim=(0, None))
    ax0.legend(fontsize=7)
    fig.suptitle(f"MPM sand, {cell}: policies side by side", fontsize=9)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def fig_per_terrain(runs: list[tuple[str, list[dict[str, Any]]]], path: str | Path, scenario: str = "straight") -> Path:
    """The per-terrain table as bars: per terrain, each policy's success rate and mean sinkage on ``scenario``.

    Left: success rate [%] with its 95 % Wilson interval, the episode count on each bar (a row short of the paper's
    100 shows it); right: mean sinkage of the lowest sole point [cm]. ``runs``: (policy label, its episodes).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    terrains = list(dict.fromkeys(r["terrain"] for _, rs in runs for r in rs if r["scenario"] == scenario))
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(10, 3.6), constrained_layout=True)
    width = 0.8 / max(len(runs), 1)
    x = np.arange(len(terrains))
    for k, (label, rs) in enumerate(runs):
        cells = [[r for r in rs if r["terrain"] == t and r["scenario"] == scenario] for t in terrains]
        n, rate, ci = _success_with_interval(cells)
        sink = [100.0 * float(np.nanmean([r["mean_sinkage"] for r in c])) if c else np.nan for c in cells]
        xk = x + (k - 0.5 * (len(runs) - 1)) * width
        ax0.bar(xk, rate, width, yerr=np.vstack([rate - ci[:, 0], ci[:, 1] - rate]), capsize=2, label=label)
        ax1.bar(xk, sink, width, label=label)
        for xi, hi, ni in zip(xk, ci[:, 1], n, strict=True):  # above the interval; upright where bars are narrow
            if ni:
                ax0.text(xi, min(float(np.nan_to_num(hi)) + 1.5, 96.0), str(int(ni)), ha="center", va="bottom",
                         fontsize=6, rotation=90 if width < 0.3 else 0)  # fmt: skip
    for ax in (ax0, ax1):
        ax.set_xticks(x, [t.replace("_", " ") for t in terrains], fontsize=8, rotation=20)
    ax0.set(ylabel="success rate [%] (95 % interval)", ylim=(0, 105))
    ax1.set(ylabel="mean sinkage [cm]")
    ax0.legend(fontsize=7)
    fig.suptitle(f"MPM sand, {scenario} walks: per terrain (episodes on each bar)", fontsize=9)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def write_figures(
    rows: list[dict[str, Any]],
    out_dir: str | Path,
    policy: str,
    episode_s: float = 10.0,
    run_dirs: list[Path] | None = None,
) -> list[Path]:
    """Write the evaluation figures under ``out_dir``; return their paths.

    With recordings in ``<run dir>/recordings`` (``run_dirs``, default ``[out_dir]``) also ``fig_mpm_paths.png``:
    each (terrain, scenario) cell's recorded walks against their commanded paths (:mod:`gmloco.eval.report.figures_paths`;
    ``episode_s`` [s] is the commanded length).
    """
    paths = [fig_mpm_speed_sweep(rows, Path(out_dir) / "fig_mpm_speed_sweep.png", policy)]
    if any(r.get("layers") for r in rows):
        paths.append(fig_mpm_transition(rows, Path(out_dir) / "fig_mpm_transition.png", policy))
    from gmloco.eval.report.figures_paths import fig_paths, recordings_by_cell

    if cells := recordings_by_cell(list(run_dirs) if run_dirs is not None else [out_dir]):
        panels = [(f"{terrain} / {scenario}", recs) for (terrain, scenario), recs in cells.items()]
        try:  # a recording that cannot be read must not cost the run its summary
            paths.append(fig_paths(panels, Path(out_dir) / "fig_mpm_paths.png", episode_s, policy))
        except (ImportError, KeyError, ValueError, OSError) as exc:
            print(f"fig_mpm_paths.png skipped: a recording in {Path(out_dir) / 'recordings'} could not be read "
                  f"({type(exc).__name__}: {exc})", file=sys.stderr)  # fmt: skip
    return paths
