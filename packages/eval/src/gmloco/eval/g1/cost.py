# SPDX-License-Identifier: Apache-2.0
"""Fitting MPM cells into a time box (issue 9): start only walks that can end before it.

A cell's MPM state (millions of particles) is not checkpointed, so an episode still running at the time box is
lost with all its frames: the reach-window table rows lost two basalt shares whole (25 robots each, walking 6-8 s of their 10 s
when the box closed; ~27 GPU-minutes). ``g1.run`` therefore measures what a cell costs in its first stretch
(:class:`CellCost`: wall seconds per frame with all its lanes walking, and the build) and, when its running walks
would not end before the time box if no robot fell, stops it and rebuilds it with the lanes that do fit
(:func:`fit_lanes`); later cells of the same (terrain, scenario) get those lanes before they are built, and a lane
whose robot fell takes the next episode only while a whole walk still fits. Before anything of a (terrain,
scenario) is measured, its first cell is sized by :func:`prior_cost` (an H200's frame-cost line): a share started
near the time box then builds the lanes that can end, or nothing, instead of probing a full cell first (in the basalt and rough-sand square-window
rows, ~70 s went to each of four such probes and ~1.1 min on each of four shares in which no walk fitted). The prediction assumes no robot falls
(the worst case): robots that fall end sooner, so a fitted cell ends early rather than late.

Per-frame cost model, from the wall-clock frames of the square-window table rows (H200, 3 cm voxels, 500 sweeps, all lanes
walking; ``benchmarks/mpm_eval/frame_cost.py`` -> ``frame_cost.json``, ``fig_frame_cost.png``): 0.18M particles (one
lane) 0.059 s, 0.35M 0.083 s, 0.53M 0.098 s, 2.12M 0.288 s, 3.08M 0.400 s, 4.24M 0.534 s, 4.42M 0.549 s a frame,
i.e. 0.040 s + 0.116 s per million particles: the part that does not shrink with the sand is ~7 % of a full 25-lane
square-window frame. Lanes of one cell have the same window, so a cell's particles follow its lanes: ``frame_s(n) =
frame_s(N) (f + (1 - f) n / N)`` with the floor ``f`` = :data:`FRAME_COST_FLOOR`, taken a little above the fit:
scaled from the 25-lane frame it reads the 1-3-lane cells timed in the basalt and rough-sand square-window rows (refitted rough-sand cells, a resumed
circle) 2-10 % high and the 12- and 24-lane cells within 1 % (:data:`FIT_MARGIN` covers that).
"""

from __future__ import annotations

from dataclasses import dataclass

FRAME_COST_FLOOR = 0.08
"""Share of a measured frame's wall time that does not shrink with fewer lanes [-] (the fit above: 0.040 s of a
0.549 s frame at 4.42M particles, 7 %; the rheology sweeps' launches, the robots' MuJoCo step, the coupling).
0.10 served until cells below 12 lanes were timed (the reach-window and square-window table rows)."""
FIT_MARGIN = 1.1
"""Predicted stepping time is multiplied by this before it is compared with the time left [-]."""
FIT_PROBE_S = 30.0
"""Stepping time after which a cell's frame cost is measured and its fit decided [s] (~55-80 frames at the
tables' sizes: past the capture's first slow frames, before most falls)."""


PRIOR_FRAME_S_AT_ZERO = 0.040
"""Wall seconds of a frame that do not grow with the particles, on an H200 at 500 sweeps [s] (frame-cost fit)."""
PRIOR_FRAME_S_PER_MILLION = 0.116
"""Wall seconds of a frame per million particles, on an H200 at 500 sweeps [s] (frame-cost fit of the square-window table rows)."""
PRIOR_SWEEPS = 500
"""Rheology sweeps the prior was measured at; fewer scale its particle term down, more leave it (optimistic)."""
PRIOR_BUILD_S = 25.0
"""Seconds to build and capture a cell, the fastest measured (25-41 s on H200s over the transition-course and square-window table rows) [s]."""


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


def prior_cost(particles_per_lane: int, lanes: int, sweeps: int = PRIOR_SWEEPS) -> CellCost:
    """A cell's cost before any of its kind was measured: an H200's frame-cost line [s].

    Meant to err fast: the build is the fastest measured, the particle term is scaled down for fewer rheology
    sweeps and not up for more, so a slower device cuts no lane by it (its cells are cut by their probe instead).
    A device much faster than an H200 would see lanes cut near the time box that would have fit.

    Args:
        particles_per_lane: Particles of one lane's sand window.
        lanes: Lanes (robots) of the cell.
        sweeps: The solver's rheology sweeps (``max_iterations``).
    """
    per_million = PRIOR_FRAME_S_PER_MILLION * min(1.0, sweeps / PRIOR_SWEEPS)
    frame_s = PRIOR_FRAME_S_AT_ZERO + per_million * particles_per_lane * lanes / 1e6
    return CellCost(lanes=lanes, frame_s=frame_s, build_s=PRIOR_BUILD_S)
