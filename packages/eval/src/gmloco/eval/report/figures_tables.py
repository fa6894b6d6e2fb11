# SPDX-License-Identifier: Apache-2.0
"""A figure per MPM table, and GM-Loco's adaptation figure over the three-layer transition course.

Each ``fig_table_*`` draws one table of :mod:`gmloco.eval.report.tables_mpm` from the rows ``paper_tables`` writes, so a
figure shows exactly the table's numbers:

* :func:`fig_table_terrains`: per (policy, terrain, scenario) row, success rate with its 95 % interval, velocity
  error [m/s], heading error [deg] and DTW path error [m];
* :func:`fig_table_speeds`: success rate [%] per row and commanded speed, as a map;
* :func:`fig_table_ablation`: per terrain and policy, straight and circle success side by side, and the circle's
  DTW path error;
* :func:`fig_table_per_terrain`: per terrain, each policy's success and tracking errors;
* :func:`fig_table_transition`: per policy, decoded eta, swing apex and lift on each medium in walking order.

:func:`fig_adaptation` is the paper's adaptation figure: along the transition course (basalt -> dry sand -> poppy
seed, media shaded), the decoded stiffness eta and the swing clearance. Per medium it draws the episodes' means
(``episodes.jsonl`` ``layers``: every walk that reached it), and over the course position the recorded walks
(``recordings/transition__*.mcap``): each foot's sole height above the local surface, its swing apexes marked,
and the decoded eta where the recording holds ``/student/eta`` (:func:`adaptation_trace`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.logs import read_log

__all__ = [
    "AdaptationTrace",
    "adaptation_trace",
    "fig_adaptation",
    "fig_table_ablation",
    "fig_table_per_terrain",
    "fig_table_speeds",
    "fig_table_terrains",
    "fig_table_transition",
    "swing_apexes",
]


def _plt() -> Any:
    """matplotlib.pyplot on the Agg backend (imported lazily)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig: Any, path: str | Path) -> Path:
    """Write the figure (temporary file + replace) and close it."""
    plt = _plt()
    path = Path(path)
    tmp = path.with_name(path.stem + ".tmp.png")
    fig.savefig(tmp, dpi=120)
    plt.close(fig)
    tmp.replace(path)
    return path


def _grouped_bars(ax: Any, groups: list[str], series: dict[str, list[float]], fmt: str = "{:.2g}") -> None:
    """Bars of each series side by side per group, each labelled with its value (a 0 shows; NaN: no bar)."""
    width = 0.8 / max(len(series), 1)
    x = np.arange(len(groups))
    for k, (label, values) in enumerate(series.items()):
        xk = x + (k - 0.5 * (len(series) - 1)) * width
        v = np.asarray(values, dtype=float)
        ax.bar(xk, v, width, label=label, color=f"C{k}")
        for xi, vi in zip(xk, v, strict=True):
            if math.isfinite(vi):
                ax.text(xi, vi, fmt.format(vi), ha="center", va="bottom", fontsize=6, color=f"C{k}")
    ax.set_xticks(x, [g.replace("_", " ") for g in groups], fontsize=7, rotation=20)


def fig_table_terrains(rows: Sequence[Mapping[str, Any]], path: str | Path) -> Path:
    """``table_terrains`` records (``tables.json`` ``rows``): success, velocity, heading and path error per row."""
    plt = _plt()
    labels = [f"{r['policy']} / {r['terrain']} / {r['scenario']} (n={r['episodes']})" for r in rows]
    y = np.arange(len(rows))
    fig, axes = plt.subplots(1, 4, figsize=(14, 0.6 + 0.32 * max(len(rows), 1)), sharey=True, constrained_layout=True)
    rate = np.array([float(r["success_rate_pct"]) for r in rows])
    lo = rate - np.array([float(r["success_lo95_pct"]) for r in rows])
    hi = np.array([float(r["success_hi95_pct"]) for r in rows]) - rate
    axes[0].barh(y, rate, xerr=np.vstack([lo, hi]), capsize=2, color="tab:green")
    axes[0].set(xlabel="success [%] (95 % interval)", xlim=(0, 105))
    for ax, key, label in zip(axes[1:], ("vel_error_mps", "heading_error_deg", "path_error_m"),
                              ("velocity error [m/s]", "heading error [deg]", "DTW path error [m]"), strict=True):  # fmt: skip
        values = np.array([float(r.get(key, math.nan)) for r in rows])
        ax.barh(y, values)
        for yi, v in zip(y, values, strict=True):
            if not math.isfinite(v):
                ax.text(0.0, yi, " not recorded", va="center", fontsize=6, color="0.5")
        ax.set(xlabel=label)
    axes[0].set_yticks(y, labels, fontsize=7)
    axes[0].invert_yaxis()
    fig.suptitle("MPM evaluation per (policy, terrain, scenario) (table_terrains)", fontsize=9)
    return _save(fig, path)


def fig_table_speeds(header: list[str], body: list[list[Any]], path: str | Path) -> Path:
    """``table_speeds`` (header ``policy, terrain, scenario, v=... m/s``): success [%] per row and speed as a map."""
    plt = _plt()
    speeds = header[3:]
    grid = np.array([[float(v) for v in row[3:]] for row in body], dtype=float).reshape(len(body), len(speeds))
    fig, ax = plt.subplots(figsize=(2.0 + 1.1 * len(speeds), 0.8 + 0.32 * max(len(body), 1)), constrained_layout=True)
    image = ax.imshow(np.ma.masked_invalid(grid), vmin=0, vmax=100, cmap="viridis", aspect="auto")
    for (i, j), v in np.ndenumerate(grid):
        ax.text(j, i, "-" if not math.isfinite(v) else f"{v:.0f}", ha="center", va="center", fontsize=7,
                color="w" if math.isfinite(v) and v < 50 else "k")  # fmt: skip
    ax.set_xticks(range(len(speeds)), speeds, fontsize=7)
    ax.set_yticks(range(len(body)), [" / ".join(str(c) for c in row[:3]) for row in body], fontsize=7)
    fig.colorbar(image, ax=ax, label="success [%]")
    ax.set_title("success per commanded speed (table_speeds)", fontsize=9)
    return _save(fig, path)


def fig_table_ablation(body: list[list[Any]], path: str | Path) -> Path:
    """``table_ablation`` rows (``ABLATION_COLUMNS``): straight and circle success, circle DTW, per terrain."""
    from gmloco.eval.report.tables_mpm import ABLATION_COLUMNS

    plt = _plt()
    col = {c: i for i, c in enumerate(ABLATION_COLUMNS)}
    terrains = list(dict.fromkeys(r[col["terrain"]] for r in body))
    policies = list(dict.fromkeys(r[col["policy"]] for r in body))
    at = {(r[col["terrain"]], r[col["policy"]]): r for r in body}
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6), constrained_layout=True)
    for ax, key, label in zip(axes, ("straight_success_pct", "circle_success_pct", "circle_path_error_m"),
                              ("straight success [%]", "circle success [%]", "circle DTW path error [m]"), strict=True):  # fmt: skip
        series = {p: [float(at[(t, p)][col[key]]) if (t, p) in at else math.nan for t in terrains] for p in policies}
        _grouped_bars(ax, terrains, series, "{:.0f}" if key.endswith("pct") else "{:.2g}")
        ax.set(ylabel=label)
        if key.endswith("pct"):
            ax.set_ylim(0, 105)
    axes[0].legend(fontsize=7)
    fig.suptitle("contact-model ablation (table_ablation)", fontsize=9)
    return _save(fig, path)


def fig_table_per_terrain(header: list[str], body: list[list[Any]], path: str | Path) -> Path:
    """``table_per_terrain`` (header ``terrain, <policy>: <metric>, ...``): a panel per metric, policies as bars."""
    plt = _plt()
    metrics = list(dict.fromkeys(h.split(": ", 1)[1] for h in header[1:]))
    policies = list(dict.fromkeys(h.split(": ", 1)[0] for h in header[1:]))
    terrains = [str(r[0]) for r in body]
    fig, axes = plt.subplots(1, len(metrics), figsize=(3.4 * len(metrics), 3.4), constrained_layout=True)
    for ax, metric in zip(np.atleast_1d(axes), metrics, strict=True):
        series = {p: [float(r[header.index(f"{p}: {metric}")]) for r in body] for p in policies}
        _grouped_bars(ax, terrains, series, "{:.0f}" if "%" in metric else "{:.2g}")
        ax.set(ylabel=metric)
        if "%" in metric:
            ax.set_ylim(0, 105)
    np.atleast_1d(axes)[0].legend(fontsize=7)
    fig.suptitle("per terrain, straight walks (table_per_terrain)", fontsize=9)
    return _save(fig, path)


def fig_table_transition(body: list[list[Any]], path: str | Path) -> Path:
    """``table_transition`` rows (``policy`` + ``TRANSITION_COLUMNS``): eta, apex and lift per medium and policy."""
    from gmloco.eval.report.tables_mpm import TRANSITION_COLUMNS

    plt = _plt()
    col = {c: i + 1 for i, c in enumerate(TRANSITION_COLUMNS)}
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.4), constrained_layout=True)
    for key in dict.fromkeys((r[0], r[col["scenario"]]) for r in body):
        rs = [r for r in body if (r[0], r[col["scenario"]]) == key]
        media = [r[col["medium"]] for r in rs]
        for ax, name in zip(axes, ("eta_decoded", "swing_apex_cm", "swing_lift_cm"), strict=True):
            ax.plot(media, [float(r[col[name]]) for r in rs], "o-", label=" / ".join(key))
    for ax, label in zip(axes, ("decoded eta [-]", "swing apex above the surface [cm]", "swing lift [cm]"),
                         strict=True):  # fmt: skip
        ax.set(ylabel=label)
    axes[0].legend(fontsize=7)
    fig.suptitle("transition course per medium, in walking order (table_transition)", fontsize=9)
    return _save(fig, path)


@dataclass(frozen=True)
class AdaptationTrace:
    """One recorded transition walk along the course."""

    x: np.ndarray
    """Pelvis course position [m], [T]."""
    height: np.ndarray
    """Lowest sole point of each foot above the local surface [m], [T, 2] (negative: sunk)."""
    contact: np.ndarray
    """Foot in contact (vertical sand force above 40 N), [T, 2]."""
    eta: np.ndarray | None
    """Decoded stiffness [-] at each sample, [T] (None: the recording holds no ``/student/eta``)."""
    speed: float
    """Commanded forward speed [m/s]."""


def adaptation_trace(recording: str | Path) -> AdaptationTrace:
    """Read an evaluation recording (``g1.record`` schema) as its course position, soles and decoded eta.

    Raises:
        KeyError: The recording lacks odometry or the simulated foot contact (not an evaluation episode).
    """
    with warnings.catch_warnings():  # a recording has no run_end record by design; the reader warns about it
        warnings.simplefilter("ignore")
        lg = read_log(recording)
    t, pos = lg.signal("odom.position")
    ts, sink = lg.signal("sim.sinkage")
    _, contact = lg.signal("sim.in_contact")
    _, vx = lg.signal("command.lin_vel_x")
    x = np.interp(np.asarray(ts, dtype=float), np.asarray(t, dtype=float), np.asarray(pos, dtype=float)[:, 0])
    eta = None
    if lg.has("student.eta"):
        te, e = lg.signal("student.eta")
        eta = np.interp(np.asarray(ts, dtype=float), np.asarray(te, dtype=float), np.asarray(e, dtype=float).ravel())
    return AdaptationTrace(x=x, height=-np.asarray(sink, dtype=float), contact=np.asarray(contact, dtype=bool),
                           eta=eta, speed=float(np.asarray(vx, dtype=float).ravel()[0]))  # fmt: skip


def swing_apexes(height: np.ndarray, contact: np.ndarray, min_steps: int = 3) -> list[tuple[int, float]]:
    """Return (sample, apex [m]) of every completed swing of one foot.

    A swing is a run of at least ``min_steps`` samples out of contact that ends in a touchdown (the open swing at
    the end does not count); its apex is its highest sole point.

    Args:
        height: Sole height above the local surface [m], [T].
        contact: Foot in contact, [T].
        min_steps: Shortest swing counted [samples] (shorter runs are contact flicker).
    """
    swing = ~np.asarray(contact, dtype=bool)
    edges = np.diff(np.concatenate([[0], swing.astype(np.int8), [0]]))
    out = []
    for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True):
        if b - a >= min_steps and b < len(swing):
            k = a + int(np.argmax(height[a:b]))
            out.append((int(k), float(height[k])))
    return out


def _layer_spans(terrain: Any, x_max: float) -> list[tuple[str, float, float]]:
    """(medium, start, end) [m] of each layer of the course up to ``x_max`` (the first from -inf, shown from 0)."""
    spans = []
    for k, medium in enumerate(terrain.materials):
        a = 0.0 if k == 0 else terrain.layer_start + k * terrain.layer_length
        b = terrain.layer_start + (k + 1) * terrain.layer_length if k < len(terrain.materials) - 1 else x_max
        spans.append((medium, a, max(b, a)))
    return spans


def fig_adaptation(
    episodes: list[dict[str, Any]], recordings: Sequence[str | Path], path: str | Path, label: str, terrain: Any = None
) -> Path:
    """GM-Loco's adaptation figure on the transition course (see the module docstring).

    Args:
        episodes: The policy's ``episodes.jsonl`` rows; those with ``layers`` give the per-medium means.
        recordings: Recorded transition walks (``recordings/transition__*.mcap``), any number.
        path: Output PNG.
        label: Policy label for the title.
        terrain: The course (``window_terrain.MpmTerrainCfg``; default ``terrain_cfg("transition")``).
    """
    from gmloco.eval.mpm.window_terrain import terrain_cfg
    from gmloco.eval.report.tables_mpm import table_transition

    plt = _plt()
    terrain = terrain or terrain_cfg("transition")
    traces = [adaptation_trace(r) for r in recordings]
    x_max = max([float(np.max(tr.x)) for tr in traces] + [terrain.layer_start + len(terrain.materials) * 3.0])
    spans = _layer_spans(terrain, x_max)
    means = {r[1]: r for r in table_transition([e for e in episodes if e.get("layers")])}
    fig, (ax0, ax1) = plt.subplots(2, 1, figsize=(10, 6), sharex=True, constrained_layout=True)
    for k, (medium, a, b) in enumerate(spans):
        for ax in (ax0, ax1):
            ax.axvspan(a, b, color=f"C{k}", alpha=0.08)
        ax0.text(0.5 * (a + b), 1.02, medium.replace("_", " "), transform=ax0.get_xaxis_transform(), ha="center",
                 fontsize=8)  # fmt: skip
        if medium in means:
            row = means[medium]
            ax0.hlines(row[3], a, b, colors="k", lw=2, label="episodes' mean" if k == 0 else None)
            ax1.hlines(row[4] / 100.0, a, b, colors="k", lw=2, label="episodes' mean apex" if k == 0 else None)
            ax1.text(0.5 * (a + b), row[4] / 100.0, f" n={row[2]}", fontsize=7, va="bottom")
    for tr in traces:
        if tr.eta is not None:
            ax0.plot(tr.x, tr.eta, lw=0.8, label=f"walk at {tr.speed:g} m/s")
        for foot in range(tr.height.shape[1]):
            line = ax1.plot(tr.x, tr.height[:, foot], lw=0.6, alpha=0.7,
                            label=f"walk at {tr.speed:g} m/s" if foot == 0 else None)  # fmt: skip
            apex = swing_apexes(tr.height[:, foot], tr.contact[:, foot])
            if apex:
                ax1.plot(tr.x[[k for k, _ in apex]], [h for _, h in apex], "v", ms=3, color=line[0].get_color())
    if not any(tr.eta is not None for tr in traces):
        ax0.text(0.01, 0.92, "the recordings hold no per-step eta: per-medium means only", fontsize=7,
                 transform=ax0.transAxes, color="0.4")  # fmt: skip
    ax0.set(ylabel="decoded stiffness eta [-]")
    ax1.set(ylabel="sole height above the surface [m]\n(swing apexes marked)", xlabel="course position x [m]")
    for ax in (ax0, ax1):
        ax.legend(fontsize=7, loc="upper right")
    n = sum(1 for e in episodes if e.get("layers"))
    fig.suptitle(f"{label}: adaptation over the transition course ({n} episodes, {len(traces)} recorded walks)",
                 fontsize=9)  # fmt: skip
    return _save(fig, path)
