# SPDX-License-Identifier: Apache-2.0
"""Scored episode rows (``episodes.jsonl``): reading them, their summary per group, success intervals, fall exits."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "FALL_EXIT_S",
    "FALL_REASONS",
    "METRIC_KEYS",
    "exit_in_fall",
    "load_episodes",
    "read_episodes",
    "summarize",
    "wilson_interval",
]


def wilson_interval(successes: int, n: int, z: float = 1.959964) -> tuple[float, float]:
    """95 % Wilson score interval of a success rate, as fractions (NaN, NaN for no episodes).

    With 100 episodes a rate of 50 % is known to about +-10 points; with 8, 8 of 8 only says "at least 68 %".
    """
    if n <= 0:
        return float("nan"), float("nan")
    p = successes / n
    denom = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    lo = 0.0 if successes <= 0 else max(0.0, centre - half)  # exact at the ends (no 3e-16 for 0 of 69)
    hi = 1.0 if successes >= n else min(1.0, centre + half)
    return lo, hi


FALL_EXIT_S = 0.75
"""An early window exit this close before the episode's fall counts as part of the fall [s]: the trailing sole of
a stumble. The reach-window runs reran the poppy-seed and deep-sand rows, whose exits (54 % and 37 % of their walks) came
0.26-0.72 s before the fall, at a window no sole left: the rows and their times alive did not change (0 of 100
each; Mann-Whitney p = 0.94 / 0.91; ``results/mpm_eval/table_rows/poppy_seed_deep_sand_reach/README.md``)."""


FALL_REASONS = ("tilt", "base_height")
"""Episode end reasons that are falls (``metrics.locomotion.episode_outcome``; not "timeout" or "success")."""


def exit_in_fall(row: dict[str, Any]) -> bool:
    """Whether an episode's early window exit came within ``FALL_EXIT_S`` before its fall (not a timeout).

    The walk was then already lost when its sole left the sand.
    """
    if not row.get("window_exit_early") or row.get("reason") not in FALL_REASONS:
        return False
    exit_s, alive = row.get("window_exit_s"), row.get("alive_s")
    return exit_s is not None and alive is not None and float(alive) - float(exit_s) <= FALL_EXIT_S


METRIC_KEYS = (
    "success", "vel_error", "heading_error_deg", "yaw_error", "path_error", "support_ratio", "max_sinkage", "mean_sinkage", "floor_reached",
    "swing_apex", "swing_lift", "eta_mean", "window_exit_early", "window_exit_turn", "heading_turn_deg",
    "sole_behind_m", "sole_ahead_m", "sole_side_m",
)  # fmt: skip


def summarize(rows: list[dict[str, Any]]) -> dict[str, float]:
    """Mean metrics per (terrain, scenario, speed), per (terrain, scenario) and over all episodes.

    The success rate comes with its 95 % Wilson interval (``success_lo95`` / ``success_hi95``).
    """
    groups: dict[str, list[dict[str, Any]]] = {"all": rows}
    for r in rows:
        groups.setdefault(f"{r['terrain']}/{r['scenario']}", []).append(r)
        groups.setdefault(f"{r['terrain']}/{r['scenario']}/v{r['speed']:g}", []).append(r)
    out: dict[str, float] = {}
    for g, rs in groups.items():
        out[f"{g}/num_episodes"] = float(len(rs))
        for k in METRIC_KEYS:
            vals = [float(r[k]) for r in rs if r.get(k) is not None and math.isfinite(float(r[k]))]
            name = "success_rate" if k == "success" else k
            out[f"{g}/{name}"] = float(np.mean(vals)) if vals else float("nan")
        out[f"{g}/success_lo95"], out[f"{g}/success_hi95"] = wilson_interval(
            sum(bool(r["success"]) for r in rs), len(rs)
        )
    return out


def read_episodes(path: Path, repair: bool = False) -> list[dict[str, Any]]:
    """Episode rows of an ``episodes.jsonl``, read up to the damage.

    Episodes are appended one line at a time, so a run killed mid-write can leave a partial last line: it is
    skipped with a note on stderr (with ``repair``, cut off the file so a resumed run appends after the last whole
    episode). A damaged line before the last means the file was edited: ValueError naming the line.
    """
    import sys

    text = path.read_text()
    lines = text.splitlines()
    rows: list[dict[str, Any]] = []
    for k, line in enumerate(lines):
        if not line.strip():
            continue
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError as exc:
            if k < len(lines) - 1:
                raise ValueError(f"{path}:{k + 1}: not an episode record ({exc}); remove the line or rerun with "
                                 "--fresh") from exc  # fmt: skip
            print(f"{path}: last line is a partial record (run stopped while writing); it is skipped",
                  file=sys.stderr)  # fmt: skip
            if repair:
                path.write_text("".join(f"{good}\n" for good in lines[:k]))
    return rows


def load_episodes(path: str | Path) -> list[dict[str, Any]]:
    """Episode rows of an evaluation run folder or of an ``episodes.jsonl`` file."""
    p = Path(path)
    p = p / "episodes.jsonl" if p.is_dir() else p
    if not p.is_file():
        raise FileNotFoundError(f"{path}: no episodes.jsonl here; pass a g1_eval output folder or its episodes.jsonl")
    if p.suffix != ".jsonl":
        raise ValueError(f"{path}: not an episodes file (.jsonl); pass a g1_eval output folder or its episodes.jsonl")
    rows = read_episodes(p)
    if not rows:
        raise ValueError(f"{p}: no episodes; run the evaluation first (python -m gmloco.eval.g1.cli)")
    return rows
