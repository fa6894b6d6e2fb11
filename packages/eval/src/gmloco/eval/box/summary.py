# SPDX-License-Identifier: Apache-2.0
"""Score the reduced-order models of the box study against MPM over matched trials."""

from __future__ import annotations

from typing import Any

import numpy as np

from gmloco.eval.metrics.box import (
    SINKAGE_FLOOR,
    TRAVEL_FLOOR,
    metric_grf_profile_error,
    metric_relative_error,
)
from gmloco.eval.studies.study_io import StudyRecords

__all__ = ["score_model", "summarize_study"]

GRAVITY = 9.81
"""Gravitational acceleration [m/s^2]."""


def score_model(
    rows: dict[int, dict], ref_rows: dict[int, dict], series: dict, ref_series: dict, weight: float
) -> dict:
    """Score one model against MPM on the trials both have.

    Args:
        rows: The model's rows by trial.
        ref_rows: MPM rows by trial.
        series: The model's series by trial ({"grf": [T, 3], ...}).
        ref_series: MPM series by trial.
        weight: Box weight m g [N].

    Returns:
        Medians over matched trials: relative errors of travel and sinkage, GRF profile RMS error / (m g),
        and the number of matched trials.
    """
    trials = sorted(set(rows) & set(ref_rows))
    if not trials:
        return {"matched_trials": 0}
    travel = metric_relative_error([rows[t]["travel"] for t in trials], [ref_rows[t]["travel"] for t in trials],
                                   TRAVEL_FLOOR)  # fmt: skip
    sink = metric_relative_error([rows[t]["sinkage"] for t in trials], [ref_rows[t]["sinkage"] for t in trials],
                                 SINKAGE_FLOOR)  # fmt: skip
    grf = [metric_grf_profile_error(np.array(series[t]["grf"]), np.array(ref_series[t]["grf"]), weight) for t in trials]
    return {
        "matched_trials": len(trials),
        "travel_rel_err_median": float(np.median(travel)),
        "sinkage_rel_err_median": float(np.median(sink)),
        "grf_profile_err_median": float(np.median(grf)),
        "travel_median": float(np.median([rows[t]["travel"] for t in trials])),
        "sinkage_median": float(np.median([rows[t]["sinkage"] for t in trials])),
        "lateral_force_median": float(np.median([rows[t]["lateral_force"] for t in trials])),
    }


def _best(scores: dict[str, dict], metric: str) -> str | None:
    """Return the model with the lowest value of ``metric`` (None if no model has it)."""
    have = {m: s[metric] for m, s in scores.items() if metric in s}
    return min(have, key=lambda m: have[m]) if have else None


def summarize_study(records: StudyRecords, cfg: Any, models: list[str]) -> dict[str, Any]:
    """Return the per-variant, per-model scores against MPM, timings, and which model is best per metric."""
    rows, series = records.rows(), {}
    for s in records.series():
        series[(s["variant"], s["trial"], s["model"])] = s  # the last line of a key wins
    weight = cfg.box.mass * GRAVITY
    out: dict[str, Any] = {"num_trials": cfg.num_trials, "box": {"size": list(cfg.box.size), "mass": cfg.box.mass},
                           "variants": {}}  # fmt: skip
    for variant in cfg.variants:
        by_model: dict[str, dict[int, dict]] = {}
        for r in rows:
            if r["variant"] == variant:
                by_model.setdefault(r["model"], {})[r["trial"]] = r
        ref = by_model.get("mpm", {})
        ser = {m: {t: series[(variant, t, m)] for t in by_model.get(m, {})} for m in models}
        scores = {m: score_model(by_model.get(m, {}), ref, ser[m], ser.get("mpm", {}), weight)
                  for m in models if m != "mpm"}  # fmt: skip
        timing = {m: {"wall_s_per_trial_median": float(np.median([r["wall_s"] for r in tr.values()])),
                      "frames_per_s_median": float(np.median([r["frames_per_s"] for r in tr.values()])),
                      "particle_count": int(max(r["particle_count"] for r in tr.values()))}
                  for m, tr in by_model.items()}  # fmt: skip
        best = {
            k: _best(scores, k) for k in ("travel_rel_err_median", "sinkage_rel_err_median", "grf_profile_err_median")
        }
        out["variants"][variant] = {
            "mpm_trials_done": len(ref),
            "mpm_travel_median": float(np.median([r["travel"] for r in ref.values()])) if ref else None,
            "mpm_sinkage_median": float(np.median([r["sinkage"] for r in ref.values()])) if ref else None,
            "mpm_lateral_force_median": float(np.median([r["lateral_force"] for r in ref.values()])) if ref else None,
            "scores": scores,
            "best": best,
            "rft3d_not_best_on": [k for k, m in best.items() if m is not None and m != "rft3d"],
            "timing": timing,
        }
    return out
