# SPDX-License-Identifier: Apache-2.0
"""Fitting MPM cells into a time box: the frame-cost model and the lane count it picks."""

from __future__ import annotations

import pytest

from gmloco.eval.g1.cost import (
    FIT_MARGIN,
    FRAME_COST_FLOOR,
    PRIOR_BUILD_S,
    CellCost,
    cell_seconds,
    fit_lanes,
    frame_seconds,
    prior_cost,
)


def test_frame_cost_is_linear_in_lanes_above_a_floor() -> None:
    """All lanes cost the measured frame; none would cost the floor; the cost per lane is constant between."""
    cost = CellCost(lanes=25, frame_s=0.56, build_s=35.0)
    assert frame_seconds(cost, 25) == pytest.approx(0.56)
    assert frame_seconds(cost, 0) == pytest.approx(FRAME_COST_FLOOR * 0.56)
    steps = [frame_seconds(cost, n + 1) - frame_seconds(cost, n) for n in range(25)]
    assert steps == pytest.approx([steps[0]] * 25)
    assert cell_seconds(cost, 25, 100) == pytest.approx(35.0 + FIT_MARGIN * 100 * 0.56)
    assert cell_seconds(cost, 25, 100, build=False) == pytest.approx(FIT_MARGIN * 100 * 0.56)


def test_dropped_basalt_share_would_have_kept_14_walks() -> None:
    """The reach-window runs' basalt share at 1.0 m/s, which the time box dropped whole, refit.

    25 lanes at 1.79 frames/s (wall clock), built in ~35 s, 799 s left after the build and the 30 s probe, 2000
    frames a 10 s walk. 25 lanes need ~1264 s; 14 lanes fit (predicted ~767 s), 15 do not; the real 14-lane cell,
    stepping at its particles' rate (``results/mpm_eval/frame_cost.json``), ends within the prediction.
    """
    cost = CellCost(lanes=25, frame_s=1 / 1.79, build_s=35.0)
    assert cell_seconds(cost, 25, 2000) > 799.0
    n = fit_lanes(cost, 2000, 799.0, 25)
    assert n == 14 and cell_seconds(cost, 15, 2000) > 799.0 >= cell_seconds(cost, 14, 2000)
    # wall-clock frames of the square-window table rows: 0.0399 s + 0.1155 s per million particles, 176,720 particles a lane
    real_14 = 35.0 + 2000 * (0.0399 + 0.1155 * 14 * 0.17672)
    assert real_14 < cell_seconds(cost, 14, 2000) < 799.0


def test_nothing_fits_when_one_walk_outlasts_the_time_left() -> None:
    """0 lanes when a single walk would not end; every lane when the whole cell fits; never more than asked."""
    cost = CellCost(lanes=10, frame_s=0.4, build_s=20.0)
    one = cell_seconds(cost, 1, 2000)
    assert fit_lanes(cost, 2000, one - 1.0, 10) == 0
    assert fit_lanes(cost, 2000, one, 10) == 1
    assert fit_lanes(cost, 2000, 1e9, 10) == 10 and fit_lanes(cost, 2000, 1e9, 3) == 3


@pytest.mark.parametrize(("lanes", "measured_s"), [(1, 0.0586), (2, 0.0831), (3, 0.0984), (12, 0.2876), (24, 0.5335)])
def test_model_tracks_the_frames_timed_at_fewer_lanes(lanes: int, measured_s: float) -> None:
    """The model, scaled from the full frame, reads the frames timed at fewer lanes within -1 .. +10 %.

    Scaled down from the 25-lane square-window frame (0.5493 s, 4.42M particles), it reads the frames the
    square- and reach-window rows timed with fewer lanes of the same window (``results/mpm_eval/frame_cost.json``) at most 10 % high and
    never more than 1 % low, so with the fit margin a fitted cell ends before its prediction.
    """
    predicted = frame_seconds(CellCost(lanes=25, frame_s=0.5493, build_s=0.0), lanes)
    assert 0.99 * measured_s <= predicted <= 1.10 * measured_s
    assert FIT_MARGIN * predicted > measured_s


def test_the_prior_reads_the_measured_square_window_frame_and_errs_fast() -> None:
    """25 lanes of the square window (176,720 particles each) price within 1 % of the 0.549 s frame of the basalt and rough-sand square-window rows.

    Fewer rheology sweeps scale the particle term down, more leave it as at 500 (a slower solve is left to the
    probe); the build is the fastest measured.
    """
    full = prior_cost(176_720, 25)
    assert full.lanes == 25 and full.build_s == PRIOR_BUILD_S
    assert full.frame_s == pytest.approx(0.5493, rel=0.01)
    assert prior_cost(176_720, 25, sweeps=1000).frame_s == pytest.approx(full.frame_s)
    half = prior_cost(176_720, 25, sweeps=250).frame_s
    assert half == pytest.approx(0.040 + 0.5 * (full.frame_s - 0.040))
    # a rough-sand share of the square-window rows, 6.2 min left: the prior builds 5 lanes where the probe-and-refit kept 3
    assert fit_lanes(full, 2000, 6.2 * 60, 25) == 5
