# SPDX-License-Identifier: Apache-2.0
"""How far the soles reached against the sand window, and the window that would hold a run's reach."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from gmloco.eval.g1.score import WINDOW_EXIT_GRACE_S
from gmloco.eval.mpm.window import SandWindowCfg

__all__ = ["REACH_QUANTILE", "WINDOW_TURN_SHARE", "covering_window", "reach_quantile", "report_window"]


WINDOW_SUGGEST_MARGIN_M = 0.05
"""Room a suggested window leaves beyond the soles' recorded reach [m]."""
REACH_QUANTILE = 0.975
"""A suggested window holds this quantile of the episodes' reach (a lone fall's reach would grow it for all) [-]."""
WINDOW_TURN_SHARE = 0.1
"""A suggested window is a square when at least this fraction of the early exits came from the robot's turn [-]."""


def reach_quantile(rows: list[dict[str, Any]], q: float = REACH_QUANTILE) -> tuple[float, float, float]:
    """The ``q`` quantile over episodes of the soles' reach behind / ahead of / beside the pelvis [m] (NaN: none)."""

    def one(k: str) -> float:
        vals = [float(v) for r in rows if (v := r.get(k)) is not None and math.isfinite(float(v))]
        return float(np.quantile(vals, q)) if vals else math.nan

    return one("sole_behind_m"), one("sole_ahead_m"), one("sole_side_m")


def covering_window(reach: tuple[float, float, float], window: SandWindowCfg, turned: bool) -> SandWindowCfg:
    """The smallest moving window holding ``window`` and the soles' reach (behind, ahead, beside the pelvis) [m].

    Each side grows to the reach plus ``WINDOW_SUGGEST_MARGIN_M`` where the reach passed it, rounded up to 5 cm;
    no side shrinks (the convergence check accepted the window's front and rear clearances, not less). With
    ``turned`` (walks that turned out of it) a window that does not turn becomes a square of the larger side; a
    turning window keeps its shape.
    """

    def up(x: float) -> float:
        return math.ceil(round(x / 0.05, 6)) * 0.05

    behind, ahead, side = reach
    rear = max(0.5 * window.length - window.lead, up(behind + WINDOW_SUGGEST_MARGIN_M))
    front = max(0.5 * window.length + window.lead, up(ahead + WINDOW_SUGGEST_MARGIN_M))
    width = max(window.width, 2.0 * up(side + WINDOW_SUGGEST_MARGIN_M))
    length = rear + front
    if turned and not window.turn_with_robot:
        length = width = max(length, width)
    return replace(window, length=round(length, 3), width=round(width, 3), lead=round(0.5 * (front - rear), 3))


def report_window(rows: list[dict[str, Any]], window: SandWindowCfg) -> None:
    """Say on stderr how far the soles reached against the window, and warn about episodes that left it early."""
    import sys

    reach = [max((r.get(k, math.nan) for r in rows if math.isfinite(r.get(k, math.nan))), default=math.nan)
             for k in ("sole_behind_m", "sole_ahead_m", "sole_side_m")]  # fmt: skip
    if not all(math.isfinite(x) for x in reach):
        return
    if window.moving:
        print(f"sand window: the soles reached {reach[0]:.2f} m behind the pelvis, {reach[1]:.2f} m ahead and "
              f"{reach[2]:.2f} m sideways (largest over {len(rows)} episodes); the window spans "
              f"{0.5 * window.length - window.lead:.2f} m behind, {0.5 * window.length + window.lead:.2f} m ahead and "
              f"{0.5 * window.width:.2f} m sideways ("
              + ("turning with the robot)" if window.turn_with_robot else
                 "along the grid's axes; on circles a square of the larger side)"),
              file=sys.stderr, flush=True)  # fmt: skip
    early = [r for r in rows if r.get("window_exit_early")]
    if early:
        worst = min(early, key=lambda r: r["window_exit_s"])
        turned = sum(bool(r.get("window_exit_turn")) for r in early)
        why = (f"; in {turned} of them the robot had turned and the soles were within the window's reach along its "
               "heading: a window that does not turn (--window-fixed-axes) leaves a drifting walk behind; let it "
               "turn with the robot (the default)") if turned else ""  # fmt: skip
        q = reach_quantile(rows)
        cover = covering_window(q, window, turned >= WINDOW_TURN_SHARE * len(early))
        print(f"warning: in {len(early)} of {len(rows)} episodes a sole that needed sand stood outside its sand window "
              f"more than {WINDOW_EXIT_GRACE_S} s before the episode ended (first at {worst['window_exit_s']:.2f} s, "
              f"{worst['key']}): those walks lost their support to the window, not to the sand. Lengthen the window "
              f"or move it back (--window-length, --window-lead, --window-width){why}. A window holding this run's "
              f"reach ({100 * REACH_QUANTILE:g}th percentile): --window-length {cover.length:g} --window-width {cover.width:g} --window-lead {cover.lead:g}",
              file=sys.stderr, flush=True)  # fmt: skip
