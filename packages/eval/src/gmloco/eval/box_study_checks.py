# SPDX-License-Identifier: Apache-2.0
"""Robustness checks of the box study: box-size sensitivity and MPM voxel convergence (issue 5)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.eval.study_io import StudyRecords

__all__ = ["size_sensitivity", "voxel_convergence"]

SCORE_KEYS = ("travel_rel_err_median", "sinkage_rel_err_median", "grf_profile_err_median")
"""Per-model scores against MPM that the checks compare."""


def size_sensitivity(summary: dict[str, Any]) -> dict[str, Any]:
    """Compare the study across box sizes: the ``forward`` variant and every ``size_x<scale>`` variant.

    Returns, per size variant: the MPM medians, each model's scores, and the best model per score; plus
    ``best_model_stable``: per score, whether the same model is best at every size (None if a size lacks MPM).
    """
    names = [v for v in summary["variants"] if v == "forward" or v.startswith("size_x")]
    out: dict[str, Any] = {"variants": {}}
    for v in names:
        var = summary["variants"][v]
        out["variants"][v] = {
            "mpm_trials_done": var["mpm_trials_done"],
            "mpm_travel_median": var["mpm_travel_median"],
            "mpm_sinkage_median": var["mpm_sinkage_median"],
            "scores": {m: {k: s.get(k) for k in SCORE_KEYS} for m, s in var["scores"].items()},
            "best": var["best"],
        }
    have_mpm = all(out["variants"][v]["mpm_trials_done"] > 0 for v in names)
    out["best_model_stable"] = {
        k: (len({out["variants"][v]["best"][k] for v in names}) == 1 if have_mpm and len(names) > 1 else None)
        for k in SCORE_KEYS
    }
    return out


def _mpm_by_trial(out_dir: str | Path) -> tuple[float, int, dict[tuple[str, int], dict[str, Any]]]:
    """Return (voxel size [m], rheology iterations, MPM rows keyed by (variant, trial)) of one study directory."""
    rows = [r for r in StudyRecords(out_dir).rows() if r["model"] == "mpm"]
    if not rows:
        raise ValueError(f"{out_dir}: no MPM trials (trials.csv + grf.jsonl)")
    voxels = {float(r["voxel_size"]) for r in rows}
    if len(voxels) != 1:
        raise ValueError(f"{out_dir}: MPM trials at several voxel sizes {sorted(voxels)}; use one dir per size")
    config = Path(out_dir) / "config.json"
    iterations = int(json.loads(config.read_text())["mpm"]["max_iterations"]) if config.exists() else -1
    return voxels.pop(), iterations, {(r["variant"], int(r["trial"])): r for r in rows}


def voxel_convergence(
    out_dirs: list[str | Path], travel_tol: float = 0.1, sinkage_tol: float = 0.005
) -> dict[str, Any]:
    """Compare the MPM trials that several study directories (same seed; other voxel sizes or iterations) share.

    Levels are ordered coarse to fine: voxel size descending, then rheology iterations ascending (Newton's
    Gauss-Seidel is not converged at 50 iterations, README). For each level, the median over shared trials of
    |travel - travel_finest| / travel_finest and |sinkage - sinkage_finest| [m]. ``converged``: the second-finest
    level is within ``travel_tol`` (relative) and ``sinkage_tol`` [m] of the finest (issue 5's criterion).
    """
    data = sorted(((*_mpm_by_trial(d), str(d)) for d in out_dirs), key=lambda t: (-t[0], t[1]))
    shared = sorted(set.intersection(*(set(rows) for _, _, rows, _ in data)))
    if not shared:
        raise ValueError("the directories share no (variant, trial) MPM record: run them with the same seed")
    fine = data[-1][2]
    levels = []
    for voxel, iterations, rows, d in data:
        dt = [abs(rows[k]["travel"] - fine[k]["travel"]) / max(abs(fine[k]["travel"]), 1e-2) for k in shared]
        ds = [abs(rows[k]["sinkage"] - fine[k]["sinkage"]) for k in shared]
        levels.append({
            "voxel_size": voxel, "max_iterations": iterations, "dir": d, "travel_median": float(np.median([rows[k]["travel"] for k in shared])),
            "sinkage_median": float(np.median([rows[k]["sinkage"] for k in shared])),
            "travel_rel_diff_to_finest": float(np.median(dt)), "sinkage_abs_diff_to_finest": float(np.median(ds)),
            "wall_s_per_trial_median": float(np.median([rows[k]["wall_s"] for k in shared])),
            "frames_per_s_median": float(np.median([rows[k]["frames_per_s"] for k in shared])),
            "particle_count": int(max(rows[k]["particle_count"] for k in shared)),
        })  # fmt: skip
    converged = None
    if len(levels) >= 2:
        second = levels[-2]
        converged = (
            second["travel_rel_diff_to_finest"] <= travel_tol and second["sinkage_abs_diff_to_finest"] <= sinkage_tol
        )
    return {"shared_trials": [list(k) for k in shared], "levels": levels, "converged": converged,
            "travel_tol": travel_tol, "sinkage_tol": sinkage_tol}  # fmt: skip


def write_voxel_convergence(out_dirs: list[str | Path], path: str | Path) -> dict[str, Any]:
    """Compute :func:`voxel_convergence` and write it as JSON to ``path``."""
    res = voxel_convergence(out_dirs)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(json.dumps(res, indent=1))
    return res
