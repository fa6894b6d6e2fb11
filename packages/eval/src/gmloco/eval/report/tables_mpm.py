# SPDX-License-Identifier: Apache-2.0
"""The MPM evaluation's paper-shaped tables (markdown + CSV) from the per-episode rows of ``episodes.jsonl``.

* ``table_terrains``: one row per (policy, terrain, scenario): episodes, success rate with its 95 % Wilson
  interval, velocity tracking error, heading error in degrees (GM-Loco's yaw tracking error), yaw-rate error
  [rad/s] (an extra column), DTW path error, mean sinkage, swing apex and lift (GM-Loco's
  per-terrain and contact-model tables;
  ``window_exit_pct``: episodes whose soles left the sand window early, a validity check, NaN for older runs;
  ``window_exit_turn_pct``: those of them that left it because the robot turned (the window does not turn), NaN for
  runs before the per-terrain runs; ``window_exit_fall_pct``: those of them whose exit came within ``metrics.episodes.FALL_EXIT_S``
  before the fall (a stumble's trailing sole: the walk was already lost);
  several policies' ``episodes.jsonl`` concatenated give the ablation rows).
* ``table_speeds``: success rate per commanded forward speed (rows terrain x scenario).
* ``table_ablation`` and ``table_per_terrain``: the same numbers in the paper's two layouts, built from several
  policies' ``table_terrains`` rows (``gmloco.eval.report.paper_tables``): per (terrain, policy) the straight and circular
  walks side by side (success, DTW path error), and per terrain each policy's success and tracking errors.
* ``table_transition``: on the layered ``transition`` course, per (scenario, medium): episodes that reached the
  medium, the student's mean decoded stiffness eta and the swing apex / lift there (GM-Loco's terrain-transition
  analysis); written only when the rows hold transition episodes.
* ``paper_metrics``: the ``table_terrains`` rows as ``{policy: {terrain: {scenario: {success_pct, vel_error_mps,
  heading_error_deg, path_error_m, episodes}}}}``, the keys of the paper's tables (``summary.json``).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.eval.metrics.episodes import exit_in_fall, wilson_interval

__all__ = [
    "ABLATION_COLUMNS",
    "PAPER_METRIC_KEYS",
    "PER_TERRAIN_METRICS",
    "TERRAIN_COLUMNS",
    "TRANSITION_COLUMNS",
    "paper_metrics",
    "table_ablation",
    "table_per_terrain",
    "table_speeds",
    "table_terrains",
    "table_transition",
    "write_table",
    "write_tables",
]

TERRAIN_COLUMNS = ("policy", "terrain", "scenario", "episodes", "success_rate_pct", "success_lo95_pct",
                   "success_hi95_pct", "vel_error_mps", "heading_error_deg",
                   "yaw_error_radps", "path_error_m", "mean_sinkage_cm", "swing_apex_cm", "swing_lift_cm",
                   "window_exit_pct", "window_exit_turn_pct", "window_exit_fall_pct")  # fmt: skip
"""Columns of ``table_terrains``."""


def _mean(rows: list[dict[str, Any]], key: str) -> float:
    """Mean of a finite metric over rows (NaN when none)."""
    vals = [float(r[key]) for r in rows if r.get(key) is not None and math.isfinite(float(r[key]))]
    return float(np.mean(vals)) if vals else float("nan")


def _cells(rows: list[dict[str, Any]]) -> dict[tuple[str, str], list[dict[str, Any]]]:
    """Rows grouped by (terrain, scenario), first-seen order."""
    out: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in rows:
        out.setdefault((r["terrain"], r["scenario"]), []).append(r)
    return out


def _exit_in_fall_pct(rows: list[dict[str, Any]]) -> float:
    """% of episodes whose early window exit came with their fall (``metrics.episodes.exit_in_fall``; NaN: not checked)."""
    checked = [r for r in rows if r.get("window_exit_early") is not None]
    return 100.0 * sum(exit_in_fall(r) for r in checked) / len(checked) if checked else float("nan")


def table_terrains(rows: list[dict[str, Any]], policy: str) -> list[list[Any]]:
    """Rows of ``table_terrains`` (``TERRAIN_COLUMNS``), one per (terrain, scenario)."""
    out = []
    for (terrain, scenario), rs in _cells(rows).items():
        lo, hi = wilson_interval(sum(bool(r["success"]) for r in rs), len(rs))
        out.append([policy, terrain, scenario, len(rs), 100.0 * _mean(rs, "success"), 100.0 * lo, 100.0 * hi,
                    _mean(rs, "vel_error"), _mean(rs, "heading_error_deg"),
                    _mean(rs, "yaw_error"), _mean(rs, "path_error"), 100.0 * _mean(rs, "mean_sinkage"),
                    100.0 * _mean(rs, "swing_apex"), 100.0 * _mean(rs, "swing_lift"),
                    100.0 * _mean(rs, "window_exit_early"), 100.0 * _mean(rs, "window_exit_turn"),
                    _exit_in_fall_pct(rs)])  # fmt: skip
    return out


def table_speeds(rows: list[dict[str, Any]], speeds: list[float] | None = None) -> tuple[list[str], list[list[Any]]]:
    """(header, rows) of the success rate [%] per commanded speed, one row per (terrain, scenario).

    ``speeds``: the columns (default: the speeds in ``rows``); a speed without episodes in a row is NaN.
    """
    speeds = sorted({float(r["speed"]) for r in rows}) if speeds is None else list(speeds)
    header = ["terrain", "scenario", *[f"v={v:g} m/s" for v in speeds]]
    body = []
    for (terrain, scenario), rs in _cells(rows).items():
        body.append(
            [terrain, scenario, *[100.0 * _mean([r for r in rs if r["speed"] == v], "success") for v in speeds]]
        )
    return header, body


ABLATION_COLUMNS = ("terrain", "policy", "straight_episodes", "straight_success_pct", "circle_episodes",
                    "circle_success_pct", "circle_path_error_m")  # fmt: skip
"""Columns of ``table_ablation``."""

_COL = {c: i for i, c in enumerate(TERRAIN_COLUMNS)}


def table_ablation(terrain_rows: list[list[Any]]) -> list[list[Any]]:
    """GM-Loco's contact-model ablation layout: straight and circular walks side by side per (terrain, policy).

    Columns ``ABLATION_COLUMNS``: the straight walk's success rate beside the circular walk's success rate and DTW
    path error (a scenario not run: 0 episodes, NaN). ``terrain_rows``: rows of ``table_terrains``
    (``TERRAIN_COLUMNS``, extra trailing columns ignored), several policies concatenated; terrains and policies
    keep their first-seen order, the rows grouped by terrain.
    """
    cells: dict[str, dict[str, dict[str, list[Any]]]] = {}  # terrain -> policy -> scenario -> row
    for r in terrain_rows:
        cells.setdefault(r[_COL["terrain"]], {}).setdefault(r[_COL["policy"]], {})[r[_COL["scenario"]]] = r
    nan = float("nan")
    out = []
    for terrain, policies in cells.items():
        for policy, by in policies.items():
            s, c = by.get("straight"), by.get("circle")
            out.append([terrain, policy,
                        s[_COL["episodes"]] if s else 0, s[_COL["success_rate_pct"]] if s else nan,
                        c[_COL["episodes"]] if c else 0, c[_COL["success_rate_pct"]] if c else nan,
                        c[_COL["path_error_m"]] if c else nan])  # fmt: skip
    return out


PER_TERRAIN_METRICS = (("success_rate_pct", "success %"), ("vel_error_mps", "vel error [m/s]"),
                       ("heading_error_deg", "heading error [deg]"),
                       ("yaw_error_radps", "yaw-rate error [rad/s]"))  # fmt: skip
"""The per-terrain table's metrics (``table_terrains`` column, header label)."""


def table_per_terrain(terrain_rows: list[list[Any]], scenario: str = "straight") -> tuple[list[str], list[list[Any]]]:
    """GM-Loco's per-terrain layout: one row per terrain, each policy's success and tracking errors side by side.

    For each policy: its success rate and velocity and yaw tracking errors on ``scenario`` (NaN where the policy
    did not walk that terrain). Returns (header, rows).
    """
    policies = list(dict.fromkeys(r[_COL["policy"]] for r in terrain_rows))
    terrains = list(dict.fromkeys(r[_COL["terrain"]] for r in terrain_rows if r[_COL["scenario"]] == scenario))
    at = {(r[_COL["terrain"]], r[_COL["policy"]]): r for r in terrain_rows if r[_COL["scenario"]] == scenario}
    header = ["terrain", *[f"{p}: {label}" for p in policies for _, label in PER_TERRAIN_METRICS]]
    body = [[t, *[at[(t, p)][_COL[key]] if (t, p) in at else float("nan") for p in policies
                  for key, _ in PER_TERRAIN_METRICS]] for t in terrains]  # fmt: skip
    return header, body


PAPER_METRIC_KEYS = {"success_pct": "success_rate_pct", "vel_error_mps": "vel_error_mps",
                     "heading_error_deg": "heading_error_deg", "path_error_m": "path_error_m",
                     "episodes": "episodes"}  # fmt: skip
"""Summary key of the paper's metrics -> its ``table_terrains`` column."""


def paper_metrics(terrain_rows: list[list[Any]]) -> dict[str, dict[str, dict[str, dict[str, float | int | None]]]]:
    """The paper's metrics per (policy, terrain, scenario) from ``table_terrains`` rows (NaN written as None)."""
    out: dict[str, dict[str, dict[str, dict[str, float | int | None]]]] = {}
    for r in terrain_rows:
        cell: dict[str, float | int | None] = {}
        for key, column in PAPER_METRIC_KEYS.items():
            v = r[_COL[column]]
            cell[key] = int(v) if key == "episodes" else (float(v) if math.isfinite(float(v)) else None)
        out.setdefault(r[_COL["policy"]], {}).setdefault(r[_COL["terrain"]], {})[r[_COL["scenario"]]] = cell
    return out


TRANSITION_COLUMNS = ("scenario", "medium", "episodes_reached", "eta_decoded", "swing_apex_cm", "swing_lift_cm")
"""Columns of ``table_transition``."""


def table_transition(rows: list[dict[str, Any]]) -> list[list[Any]]:
    """Rows of ``table_transition`` (``TRANSITION_COLUMNS``), one per (scenario, medium) of the layered episodes."""
    cells: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in rows:
        for layer in r.get("layers") or []:
            if layer["steps"] > 0:
                cells.setdefault((r["scenario"], layer["medium"]), []).append(layer)
    return [[scenario, medium, len(ls), _mean(ls, "eta_mean"), 100.0 * _mean(ls, "swing_apex"),
             100.0 * _mean(ls, "swing_lift")] for (scenario, medium), ls in cells.items()]  # fmt: skip


def _fmt(x: Any) -> str:
    """Markdown cell: 3 significant decimals for floats, ``-`` for NaN."""
    if isinstance(x, float):
        return "-" if not math.isfinite(x) else f"{x:.3g}" if abs(x) < 100 else f"{x:.0f}"
    return str(x)


def write_table(
    path: Path, header: list[str] | tuple[str, ...], body: list[list[Any]], md_footer: str = ""
) -> list[Path]:
    """Write ``<path>.csv`` and ``<path>.md`` (``md_footer``: text after the markdown table, e.g. a note)."""
    with path.with_suffix(".csv").open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(body)
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(_fmt(x) for x in row) + " |" for row in body]
    path.with_suffix(".md").write_text("\n".join(lines) + "\n" + md_footer)
    return [path.with_suffix(".md"), path.with_suffix(".csv")]


def write_tables(rows: list[dict[str, Any]], out_dir: str | Path, policy: str) -> list[Path]:
    """Write both tables under ``out_dir``; return their paths."""
    out = Path(out_dir)
    paths = write_table(out / "table_terrains", TERRAIN_COLUMNS, table_terrains(rows, policy))
    header, body = table_speeds(rows)
    paths += write_table(out / "table_speeds", header, body)
    if transition := table_transition(rows):
        paths += write_table(out / "table_transition", TRANSITION_COLUMNS, transition)
    return paths
