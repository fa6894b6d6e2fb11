# SPDX-License-Identifier: Apache-2.0
"""Robustness checks and extra metrics of the box study (issue 5).

Box-size sensitivity, MPM voxel / iteration convergence (with levels that failed), and the lateral force over
the impact window (peak and impulse of the force perpendicular to the launch direction: its time mean over a
run is m dv_lat / T ~ 0 for every model because the box starts and ends without lateral velocity).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.eval.studies.study_io import StudyRecords

__all__ = [
    "fig_lateral_impact",
    "impact_window",
    "lateral_impact",
    "lateral_impact_summary",
    "lateral_impact_trials",
    "size_sensitivity",
    "voxel_convergence",
    "write_voxel_convergence",
]

IMPACT_FORCE_FRACTION = 0.1
"""Contact onset: the first sample whose force magnitude exceeds this fraction of the box weight [-]."""
REST_SPEED = 0.02
"""End of the impact: after the last sample whose horizontal CoM speed is at least this [m/s]."""
IMPULSE_FLOOR = 0.5
"""Denominator floor of the lateral-impulse relative error [N s] (0.5 N s ~ 1.4 cm/s lateral speed of 35 kg)."""
LATERAL_KEYS = ("peak_lateral_over_mg", "lateral_impulse_abs", "lateral_drift")
"""Per-trial lateral metrics (see :func:`lateral_impact`)."""

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


def impact_window(time: np.ndarray, grf: np.ndarray, pos: np.ndarray, weight: float) -> tuple[int, int] | None:
    """Return the sample range [start, stop) of the impact, or None if the force never exceeds the onset level.

    Start: the first sample with |F| > ``IMPACT_FORCE_FRACTION`` m g. Stop: one past the last sample (at or after
    the start) whose horizontal CoM speed, from successive positions, is at least ``REST_SPEED``; at least start + 1.

    Args:
        time: Sample times [s], [T] (each force sample is the mean over the interval ending there).
        grf: Force of the medium on the box [N], [T, 3].
        pos: CoM positions at the sample times [m], [T, 3].
        weight: Box weight m g [N].
    """
    time, grf, pos = np.asarray(time, float), np.asarray(grf, float), np.asarray(pos, float)
    above = np.flatnonzero(np.linalg.norm(grf, axis=1) > IMPACT_FORCE_FRACTION * weight)
    if above.size == 0:
        return None
    start = int(above[0])
    speed = np.zeros(len(time))
    speed[1:] = np.linalg.norm(np.diff(pos[:, :2], axis=0), axis=1) / np.maximum(np.diff(time), 1e-12)
    moving = np.flatnonzero(speed[start:] >= REST_SPEED)
    stop = start + (int(moving[-1]) + 1 if moving.size else 1)
    return start, max(stop, start + 1)


def lateral_impact(
    time: np.ndarray, grf: np.ndarray, pos: np.ndarray, velocity_xy: tuple[float, float], weight: float
) -> dict[str, float]:
    """Return the lateral-force metrics of one trajectory over its impact window (:func:`impact_window`).

    The lateral axis is e_z x v_hat (v = launch velocity). ``peak_lateral_over_mg``: max |F_lat| / (m g);
    ``lateral_impulse_abs``: sum of |F_lat| dt over the window [N s] (the signed impulse is m dv_lat, ~0 when
    the box stops; the absolute one measures how much sideways force acted); ``lateral_impulse``: the signed
    sum [N s]; ``lateral_drift``: final minus first sampled CoM position along the lateral axis [m];
    ``impact_duration`` [s]. All zero (duration 0) when the box never touched the medium.
    """
    v = np.asarray(velocity_xy, dtype=np.float64)
    e = np.array([-v[1], v[0]]) / max(float(np.linalg.norm(v)), 1e-12)
    time, grf, pos = np.asarray(time, float), np.asarray(grf, float), np.asarray(pos, float)
    drift = float((pos[-1, :2] - pos[0, :2]) @ e)
    win = impact_window(time, grf, pos, weight)
    if win is None:
        return {"peak_lateral_over_mg": 0.0, "lateral_impulse_abs": 0.0, "lateral_impulse": 0.0,
                "lateral_drift": drift, "impact_duration": 0.0}  # fmt: skip
    dt = np.diff(time, prepend=0.0)[win[0] : win[1]]
    f_lat = grf[win[0] : win[1], :2] @ e
    return {
        "peak_lateral_over_mg": float(np.max(np.abs(f_lat)) / weight),
        "lateral_impulse_abs": float(np.sum(np.abs(f_lat) * dt)),
        "lateral_impulse": float(np.sum(f_lat * dt)),
        "lateral_drift": drift,
        "impact_duration": float(np.sum(dt)),
    }


def lateral_impact_trials(
    records: StudyRecords, velocities: dict[str, tuple[float, float]], weight: float
) -> dict[str, dict[str, dict[int, dict[str, float]]]]:
    """Return :func:`lateral_impact` of every stored series, keyed variant -> model -> trial (last line wins)."""
    per: dict[str, dict[str, dict[int, dict[str, float]]]] = {}
    for s in records.series():
        if s["variant"] in velocities:
            m = lateral_impact(s["time"], s["grf"], s["pos"], velocities[s["variant"]], weight)
            per.setdefault(s["variant"], {}).setdefault(s["model"], {})[int(s["trial"])] = m
    return per


def fig_lateral_impact(
    records: StudyRecords, velocities: dict[str, tuple[float, float]], weight: float, path: str | Path
) -> None:
    """Write the lateral-force figure (one column per variant).

    Rows: each model's peak |F_lat| / mg and |F_lat| impulse per trial (box plots over the MPM-matched trials),
    and the median over those trials of |F_lat|(t) / mg.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    per = lateral_impact_trials(records, velocities, weight)
    variants = [v for v in velocities if v in per]
    fig, axes = plt.subplots(3, len(variants), figsize=(4.8 * len(variants), 10), squeeze=False)
    for col, variant in enumerate(variants):
        models = list(per[variant])
        ref = set(per[variant].get("mpm", {}))
        for row, key, label in ((0, "peak_lateral_over_mg", "peak |F_lat| / mg"),
                                (1, "lateral_impulse_abs", "sum |F_lat| dt over impact [N s]")):  # fmt: skip
            ax = axes[row, col]
            data = [[t[key] for k, t in per[variant][m].items() if not ref or k in ref] for m in models]
            ax.boxplot(data)
            ax.set_xticks(range(1, len(models) + 1), models, rotation=30, fontsize=7)
            ax.set(ylabel=label, title=f"{variant} (MPM-matched trials)")
        ax = axes[2, col]
        by_model: dict[str, list[np.ndarray]] = {}
        v = np.asarray(velocities[variant], float)
        e = np.array([-v[1], v[0]]) / max(float(np.linalg.norm(v)), 1e-12)
        times: dict[str, np.ndarray] = {}
        for s in records.series():
            if s["variant"] == variant and (not ref or int(s["trial"]) in ref):
                by_model.setdefault(s["model"], []).append(np.abs(np.asarray(s["grf"], float)[:, :2] @ e))
                times[s["model"]] = np.asarray(s["time"], float)
        for m, fs in by_model.items():
            n = min(len(f) for f in fs)
            ax.plot(times[m][:n], np.median([f[:n] for f in fs], axis=0) / weight, lw=1.2, label=m)
        ax.set(xlabel="time [s]", ylabel="median |F_lat| / mg")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def lateral_impact_summary(
    records: StudyRecords, velocities: dict[str, tuple[float, float]], weight: float
) -> dict[str, Any]:
    """Per variant: each model's median lateral metrics, its errors against MPM on matched trials, the best model.

    Errors per trial, then the median: |peak - peak_mpm| / (m g) (``peak_lateral_err``), |impulse - impulse_mpm| /
    max(impulse_mpm, ``IMPULSE_FLOOR``) (``impulse_rel_err``), |drift - drift_mpm| [m] (``drift_abs_err``).

    Args:
        records: The study's records (series: time, grf, pos).
        velocities: Launch velocity (v_x, v_y) [m/s] of each variant to summarize.
        weight: Box weight m g [N].
    """
    per = lateral_impact_trials(records, velocities, weight)
    out: dict[str, Any] = {}
    for variant, models in per.items():
        ref = models.get("mpm", {})
        res: dict[str, Any] = {}
        for model, trials in models.items():
            entry: dict[str, Any] = {"trials": len(trials)}
            entry.update({f"{k}_median": float(np.median([t[k] for t in trials.values()])) for k in LATERAL_KEYS})
            shared = sorted(set(trials) & set(ref))
            if model != "mpm" and shared:
                a, b = [trials[t] for t in shared], [ref[t] for t in shared]
                entry["matched_trials"] = len(shared)
                entry["peak_lateral_err_median"] = float(
                    np.median(
                        [abs(x["peak_lateral_over_mg"] - y["peak_lateral_over_mg"]) for x, y in zip(a, b, strict=True)]
                    )
                )
                entry["impulse_rel_err_median"] = float(np.median([
                    abs(x["lateral_impulse_abs"] - y["lateral_impulse_abs"]) / max(y["lateral_impulse_abs"], IMPULSE_FLOOR)
                    for x, y in zip(a, b, strict=True)
                ]))  # fmt: skip
                entry["drift_abs_err_median"] = float(
                    np.median([abs(x["lateral_drift"] - y["lateral_drift"]) for x, y in zip(a, b, strict=True)])
                )
            res[model] = entry
        best, tied = {}, {}
        for k in ("peak_lateral_err_median", "impulse_rel_err_median", "drift_abs_err_median"):
            have = {m: e[k] for m, e in res.items() if k in e}
            best[k] = min(have, key=lambda m: have[m]) if have else None
            # models within 1 % of the best (e.g. every model with no lateral force at all when MPM has little)
            tied[k] = sorted(m for m, x in have.items() if best[k] and x <= 1.01 * have[best[k]] + 1e-12)
        out[variant] = {"models": res, "best": best, "within_1pct_of_best": tied}
    return out


def _mpm_by_trial(out_dir: str | Path) -> tuple[float, int, dict[tuple[str, int], dict[str, Any]]]:
    """Return (voxel size [m], rheology iterations, MPM rows keyed by (variant, trial)) of one study directory."""
    rows = [r for r in StudyRecords(out_dir).rows() if r["model"] == "mpm"]
    if not rows:
        raise ValueError(f"{out_dir}: no MPM trials (trials.csv + grf.jsonl[.gz])")
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


def _failed_level(out_dir: str | Path) -> dict[str, Any]:
    """Describe a study directory without MPM records: its numerics (config.json) and the error its log ends with.

    The log is ``<out_dir>.log`` or ``<out_dir>/run.log`` (the GPU plan's ``> $D/<name>.log``); the error is its
    last line starting with a Python exception name (``...Error``) or None.
    """
    d = Path(out_dir)
    cfg_path = d / "config.json"
    mpm = json.loads(cfg_path.read_text()).get("mpm", {}) if cfg_path.exists() else {}
    error = None
    for log in (d.parent / f"{d.name}.log", d / "run.log"):
        if log.exists():
            lines = [ln.strip() for ln in log.read_text(errors="replace").splitlines()]
            errs = [ln for ln in lines if ln.split(":")[0].endswith(("Error", "Exception"))]
            error = errs[-1] if errs else None
            break
    return {"dir": str(d), "voxel_size": mpm.get("voxel_size"), "max_iterations": mpm.get("max_iterations"),
            "error": error}  # fmt: skip


def write_voxel_convergence(out_dirs: list[str | Path], path: str | Path) -> dict[str, Any]:
    """Compute :func:`voxel_convergence` over the directories that hold MPM trials and write it as JSON to ``path``.

    Directories without MPM trials (a failed level) are listed under ``failed_levels`` with the error their log
    ends with, instead of aborting the comparison; ``converged`` then judges only the levels that ran.
    """
    ok, failed = [], []
    for d in out_dirs:
        has_mpm = any(r["model"] == "mpm" for r in StudyRecords(d).rows())
        (ok if has_mpm else failed).append(d)
    if not ok:
        raise ValueError(f"none of {list(map(str, out_dirs))} holds MPM trials")
    res = voxel_convergence(ok)
    res["failed_levels"] = [_failed_level(d) for d in failed]
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(json.dumps(res, indent=1))
    return res
