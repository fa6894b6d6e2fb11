# SPDX-License-Identifier: Apache-2.0
"""Fitting MPM cells into a time box (issue 9): start only walks that can end before it.

A cell's MPM state (millions of particles) is not checkpointed, so an episode still running at the time box is
lost with all its frames: session 21 lost two basalt shares whole (25 robots each, walking 6-8 s of their 10 s
when the box closed; ~27 GPU-minutes). ``g1_eval`` therefore measures what a cell costs in its first stretch
(:class:`CellCost`: wall seconds per frame with all its lanes walking, and the build) and, when its running walks
would not end before the time box if no robot fell, stops it and rebuilds it with the lanes that do fit
(:func:`fit_lanes`); later cells of the same (terrain, scenario) get those lanes before they are built, and a lane
whose robot fell takes the next episode only while a whole walk still fits. The prediction assumes no robot falls
(the worst case): robots that fall end sooner, so a fitted cell ends early rather than late.

Per-frame cost model, from the wall-clock frames of sessions 20-22 (H200, 3 cm voxels, 500 sweeps, all lanes
walking; ``results/mpm_eval/frame_cost.py`` -> ``frame_cost.json``, ``fig_frame_cost.png``): 0.18M particles (one
lane) 0.059 s, 0.35M 0.083 s, 0.53M 0.098 s, 2.12M 0.288 s, 3.08M 0.400 s, 4.24M 0.534 s, 4.42M 0.549 s a frame,
i.e. 0.040 s + 0.116 s per million particles: the part that does not shrink with the sand is ~7 % of a full 25-lane
square-window frame. Lanes of one cell have the same window, so a cell's particles follow its lanes: ``frame_s(n) =
frame_s(N) (f + (1 - f) n / N)`` with the floor ``f`` = :data:`FRAME_COST_FLOOR`, taken a little above the fit:
scaled from the 25-lane frame it reads the 1-3-lane cells session 22 timed (refitted rough-sand cells, a resumed
circle) 2-10 % high and the 12- and 24-lane cells within 1 % (:data:`FIT_MARGIN` covers that).
"""

from __future__ import annotations

from dataclasses import dataclass

FRAME_COST_FLOOR = 0.08
"""Share of a measured frame's wall time that does not shrink with fewer lanes [-] (the fit above: 0.040 s of a
0.549 s frame at 4.42M particles, 7 %; the rheology sweeps' launches, the robots' MuJoCo step, the coupling).
Sessions 21-22 used 0.10, set before any cell below 12 lanes was timed."""
FIT_MARGIN = 1.1
"""Predicted stepping time is multiplied by this before it is compared with the time left [-]."""
FIT_PROBE_S = 30.0
"""Stepping time after which a cell's frame cost is measured and its fit decided [s] (~55-80 frames at the
tables' sizes: past the capture's first slow frames, before most falls)."""


@dataclass(frozen=True)
class CellCost:
    """What one cell's lanes cost, measured on the machine that runs the next cell of its (terrain, scenario)."""

    lanes: int
    """Lanes (robots) that were walking while it was measured."""
    frame_s: float
    """Wall-clock seconds per MPM frame with those lanes walking [s]."""
    build_s: float
    """Seconds to build and capture the cell's scene [s] (taken as is for fewer lanes: an upper bound)."""


def frame_seconds(cost: CellCost, lanes: int) -> float:
    """Predicted wall-clock seconds per frame of the same cell with ``lanes`` lanes [s]."""
    return cost.frame_s * (FRAME_COST_FLOOR + (1.0 - FRAME_COST_FLOOR) * lanes / cost.lanes)


def cell_seconds(cost: CellCost, lanes: int, frames: int, build: bool = True) -> float:
    """Predicted wall-clock seconds of a cell of ``lanes`` lanes stepping ``frames`` frames, margin included [s]."""
    return (cost.build_s if build else 0.0) + FIT_MARGIN * frames * frame_seconds(cost, lanes)


def fit_lanes(cost: CellCost, frames: int, seconds_left: float, most: int) -> int:
    """The most lanes (0 .. ``most``) whose cell, built now, steps ``frames`` frames before ``seconds_left`` [s].

    0: not even one walk of ``frames`` frames ends in the time left.
    """
    n = most
    while n > 0 and cell_seconds(cost, n, frames) > seconds_left:
        n -= 1
    return n
