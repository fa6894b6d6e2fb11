# SPDX-License-Identifier: Apache-2.0
"""Convergence check of an MPM setting (issue 9): does a cheaper or finer setting change the walk?

Two evaluation runs of the same policy, terrain and command, one at the reference setting and one at the
candidate (another voxel size, iteration count, window or bed), are compared episode by episode:

* time alive (until the fall, or the episode length): two-sided Mann-Whitney U test (``scipy.stats``);
* success: two-sided Fisher exact test on the 2 x 2 table of successes;
* velocity, heading and yaw-rate tracking errors (the tables' metrics, per episode): two-sided Mann-Whitney U
  tests (runs older than the heading error leave that test out);
* mean sinkage of the lowest sole point: relative difference of the run means (its 95 % bootstrap interval over
  episodes is reported beside it: a difference within the tolerance whose interval reaches past it is a weak pass);
* a sole reaching the bed's rigid floor: two-sided Fisher exact test on the episodes where it did (runs older
  than that record are left out of this test).

The candidate is **accepted** when none of the tests rejects at ``alpha`` and the sinkage differs by at most
``sinkage_rel_tol``; **rejected** when any of them does; **undecided** when either run has fewer than
``min_episodes`` episodes (a verdict on a handful of episodes would be noise), or when a run folder's
``summary.json`` says it is incomplete: its time box dropped the episodes still running, which are the ones that
lived longest, so its sample is biased toward early falls (resume it with the same ``--out`` first). Acceptance
means "no difference that these episodes can detect", so the number of episodes is part of every verdict.

    python -m gmloco.eval.studies.convergence --reference REF_RUN [REF_RUN ...] --candidate RUN [RUN ...]
        [--out verdict.json]

where each RUN is an evaluation output folder (its ``episodes.jsonl``) or the file itself; several runs of one
setting are pooled.
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from gmloco.eval.metrics.episodes import load_episodes

__all__ = ["ConvergenceCfg", "Verdict", "compare_runs", "incomplete_runs", "main"]

Decision = Literal["accepted", "rejected", "undecided"]


@dataclass(frozen=True)
class ConvergenceCfg:
    """Thresholds of the check."""

    alpha: float = 0.05
    """Significance level of the time-alive and success tests [-]."""
    sinkage_rel_tol: float = 0.15
    """Largest accepted relative difference of the mean sinkage [-]."""
    min_episodes: int = 8
    """Fewer episodes in either run: undecided."""


@dataclass(frozen=True)
class Verdict:
    """Outcome of one comparison; every number the decision used."""

    decision: Decision
    reasons: tuple[str, ...]
    episodes: tuple[int, int]
    """Episodes of the candidate and of the reference (every pair below is in this order)."""
    alive_median_s: tuple[float, float]
    """Median time alive, candidate and reference [s]."""
    alive_p: float
    success: tuple[int, int]
    """Successful episodes, candidate and reference."""
    success_p: float
    vel_error_median: tuple[float, float]
    """Median velocity tracking error, candidate and reference [m/s]."""
    vel_error_p: float
    yaw_error_median: tuple[float, float]
    """Median yaw tracking error, candidate and reference [rad] (rad/s for circle commands)."""
    yaw_error_p: float
    sinkage_mean_m: tuple[float, float]
    """Mean sinkage of the lowest sole point, candidate and reference [m]."""
    sinkage_rel_diff: float
    """|candidate - reference| / reference of the mean sinkage."""
    sinkage_rel_ci95: tuple[float, float] = (math.nan, math.nan)
    """95 % bootstrap interval of (candidate - reference) / reference of the mean sinkage (signed) [-]."""
    floor_reached: tuple[int, int] = (0, 0)
    """Episodes in which a sole reached the bed's rigid floor, candidate and reference."""
    floor_p: float = 1.0
    """Two-sided Fisher p-value of the floor counts (1.0 when a run does not record them)."""
    heading_error_median: tuple[float, float] = (math.nan, math.nan)
    """Median heading error (the paper's yaw tracking error), candidate and reference [deg]."""
    heading_error_p: float = 1.0
    """Two-sided Mann-Whitney p-value of the heading errors (1.0 when a run does not record them)."""


def _episodes_wanted(cfg: dict[str, Any]) -> int | str:
    """Episodes a run's config asks for: its share (``shard`` of ``shards``) of every (terrain, scenario) cell."""
    n = cfg.get("num_episodes")
    if not isinstance(n, int):
        return "?"
    cells = len(cfg.get("terrains") or [None]) * len(cfg.get("scenarios") or [None])
    return cells * len(range(int(cfg.get("shard", 0)), n, int(cfg.get("shards", 1))))


def incomplete_runs(paths: list[str | Path]) -> list[str]:
    """Why each run folder among ``paths`` whose ``summary.json`` says ``complete: false`` is a biased sample."""
    out = []
    for path in paths:
        summary = Path(path) / "summary.json"
        if Path(path).is_dir() and summary.is_file():
            doc = json.loads(summary.read_text())
            if doc.get("complete") is False:
                kept = len(load_episodes(path))
                wanted = _episodes_wanted(doc.get("cfg", {}))
                out.append(f"{path} is incomplete ({kept} of {wanted} episodes): its time box dropped the episodes "
                           "still running, the longest-lived, so its sample leans to early falls; resume it (same "
                           "--out) and compare again")  # fmt: skip
    return out


def _cells(rows: list[dict[str, Any]]) -> set[tuple[str, str, float]]:
    return {(r["terrain"], r["scenario"], float(r["speed"])) for r in rows}


def _metric(rows: list[dict[str, Any]], key: str) -> np.ndarray:
    """One per-episode metric; episodes without it (``None``) are left out."""
    return np.array([r[key] for r in rows if r.get(key) is not None], dtype=float)


def _mw_p(cand: np.ndarray, ref: np.ndarray) -> float:
    """Two-sided Mann-Whitney p-value; 1.0 where either side is empty (nothing to compare)."""
    from scipy.stats import mannwhitneyu

    if len(cand) == 0 or len(ref) == 0:
        return 1.0
    return float(mannwhitneyu(cand, ref, alternative="two-sided").pvalue)


def _sinkage_ci(cand: np.ndarray, ref: np.ndarray, n_boot: int = 2000, seed: int = 0) -> tuple[float, float]:
    """95 % percentile-bootstrap interval of (mean(cand) - mean(ref)) / mean(ref), episodes resampled per run."""
    cand, ref = cand[np.isfinite(cand)], ref[np.isfinite(ref)]  # as the means of the check (nanmean)
    if len(cand) == 0 or len(ref) == 0:
        return (math.nan, math.nan)
    rng = np.random.default_rng(seed)
    mc = cand[rng.integers(0, len(cand), (n_boot, len(cand)))].mean(axis=1)
    mr = ref[rng.integers(0, len(ref), (n_boot, len(ref)))].mean(axis=1)
    ok = mr != 0.0
    rel = (mc[ok] - mr[ok]) / mr[ok]
    lo, hi = np.percentile(rel, [2.5, 97.5])
    return (float(lo), float(hi))


def _floor_test(cand: list[dict[str, Any]], ref: list[dict[str, Any]]) -> tuple[tuple[int, int], float]:
    """Counts of episodes whose sole reached the floor (candidate, reference) and the Fisher p-value."""
    from scipy.stats import fisher_exact

    c = [bool(r["floor_reached"]) for r in cand if r.get("floor_reached") is not None]
    f = [bool(r["floor_reached"]) for r in ref if r.get("floor_reached") is not None]
    counts = (sum(c), sum(f))
    if not c or not f:
        return counts, 1.0
    table = [[counts[0], len(c) - counts[0]], [counts[1], len(f) - counts[1]]]
    return counts, float(fisher_exact(table, alternative="two-sided").pvalue)  # pyright: ignore[reportAttributeAccessIssue]


def compare_runs(
    ref: list[dict[str, Any]],
    cand: list[dict[str, Any]],
    cfg: ConvergenceCfg | None = None,
    biased: list[str] | None = None,
) -> Verdict:
    """Compare the candidate setting's episodes with the reference's (see the module docstring).

    ``biased``: reasons why a run's sample is not representative (``incomplete_runs``); any makes it undecided.

    Raises:
        ValueError: The runs score different (terrain, scenario, speed) cells, so they are not the same experiment.
    """
    from scipy.stats import fisher_exact

    cfg = cfg or ConvergenceCfg()
    if _cells(ref) != _cells(cand):
        raise ValueError(
            f"the runs cover different (terrain, scenario, speed) cells: {sorted(_cells(ref))} vs "
            f"{sorted(_cells(cand))}; compare runs of the same policy, terrain and command"
        )
    a_ref = np.array([r["alive_s"] for r in ref], dtype=float)
    a_cand = np.array([r["alive_s"] for r in cand], dtype=float)
    s_ref, s_cand = sum(bool(r["success"]) for r in ref), sum(bool(r["success"]) for r in cand)
    k_ref = float(np.nanmean([r["mean_sinkage"] for r in ref]))
    k_cand = float(np.nanmean([r["mean_sinkage"] for r in cand]))
    alive_p = _mw_p(a_cand, a_ref)
    tracking = {k: (_metric(cand, k), _metric(ref, k)) for k in ("vel_error", "heading_error_deg", "yaw_error")}
    track_p = {k: _mw_p(c, r) for k, (c, r) in tracking.items()}
    track_med = {k: (float(np.median(c)) if len(c) else math.nan, float(np.median(r)) if len(r) else math.nan)
                 for k, (c, r) in tracking.items()}  # fmt: skip
    table = [[s_cand, len(cand) - s_cand], [s_ref, len(ref) - s_ref]]
    success_p = float(fisher_exact(table, alternative="two-sided").pvalue)  # pyright: ignore[reportAttributeAccessIssue]
    rel = abs(k_cand - k_ref) / abs(k_ref) if k_ref else math.inf
    reasons = []
    if alive_p < cfg.alpha:
        reasons.append(f"time alive differs (Mann-Whitney p = {alive_p:.3g} < {cfg.alpha})")
    if success_p < cfg.alpha:
        reasons.append(f"success differs ({s_cand}/{len(cand)} vs {s_ref}/{len(ref)}, Fisher p = {success_p:.3g})")
    for key, name in (("vel_error", "velocity tracking error"), ("heading_error_deg", "heading error"),
                      ("yaw_error", "yaw-rate tracking error")):  # fmt: skip
        if track_p[key] < cfg.alpha:
            c, r = track_med[key]
            reasons.append(f"{name} differs (median {c:.3g} vs {r:.3g}, Mann-Whitney p = {track_p[key]:.3g})")
    if rel > cfg.sinkage_rel_tol:
        reasons.append(f"mean sinkage differs by {rel:.0%} (> {cfg.sinkage_rel_tol:.0%})")
    floor, floor_p = _floor_test(cand, ref)
    if floor_p < cfg.alpha:
        reasons.append(f"a sole reached the floor in {floor[0]} vs {floor[1]} episodes (Fisher p = {floor_p:.3g})")
    decision: Decision = "rejected" if reasons else "accepted"
    if min(len(ref), len(cand)) < cfg.min_episodes:
        decision = "undecided"
        reasons.insert(0, f"too few episodes ({len(cand)} vs {len(ref)}; at least {cfg.min_episodes} each)")
    if biased:
        decision = "undecided"
        reasons[:0] = biased
    sink_ci = _sinkage_ci(_metric(cand, "mean_sinkage"), _metric(ref, "mean_sinkage"))
    return Verdict(decision, tuple(reasons), (len(cand), len(ref)), (float(np.median(a_cand)), float(np.median(a_ref))),
                   alive_p, (s_cand, s_ref), success_p, track_med["vel_error"], track_p["vel_error"],
                   track_med["yaw_error"], track_p["yaw_error"], (k_cand, k_ref), rel, sink_ci, floor,
                   floor_p, track_med["heading_error_deg"], track_p["heading_error_deg"])  # fmt: skip


def main(argv: list[str] | None = None) -> Verdict:
    """Command line: compare two runs, print the verdict, optionally write it as JSON."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--reference", nargs="+", required=True, help="g1_eval run folders at the reference setting")
    p.add_argument("--candidate", nargs="+", required=True, help="g1_eval run folders at the setting under test")
    p.add_argument("--alpha", type=float, default=ConvergenceCfg.alpha)
    p.add_argument("--sinkage-rel-tol", type=float, default=ConvergenceCfg.sinkage_rel_tol)
    p.add_argument("--min-episodes", type=int, default=ConvergenceCfg.min_episodes)
    p.add_argument("--out", type=Path, default=None, help="write the verdict as JSON here")
    a = p.parse_args(argv)
    cfg = ConvergenceCfg(alpha=a.alpha, sinkage_rel_tol=a.sinkage_rel_tol, min_episodes=a.min_episodes)
    try:
        ref = [row for path in a.reference for row in load_episodes(path)]
        cand = [row for path in a.candidate for row in load_episodes(path)]
        v = compare_runs(ref, cand, cfg, biased=incomplete_runs([*a.reference, *a.candidate]))
    except (FileNotFoundError, ValueError) as exc:
        p.error(str(exc))
    print(f"{v.decision}: candidate {v.episodes[0]} episodes vs reference {v.episodes[1]}")
    print(f"  time alive median {v.alive_median_s[0]:.2f} vs {v.alive_median_s[1]:.2f} s (p = {v.alive_p:.3g})")
    print(f"  success {v.success[0]}/{v.episodes[0]} vs {v.success[1]}/{v.episodes[1]} (p = {v.success_p:.3g})")
    print(f"  velocity error median {v.vel_error_median[0]:.3f} vs {v.vel_error_median[1]:.3f} m/s "
          f"(p = {v.vel_error_p:.3g}); yaw error {v.yaw_error_median[0]:.3f} vs {v.yaw_error_median[1]:.3f} "
          f"(p = {v.yaw_error_p:.3g}); heading error {v.heading_error_median[0]:.2f} vs "
          f"{v.heading_error_median[1]:.2f} deg (p = {v.heading_error_p:.3g})")  # fmt: skip
    lo, hi = v.sinkage_rel_ci95
    print(f"  mean sinkage {100 * v.sinkage_mean_m[0]:.1f} vs {100 * v.sinkage_mean_m[1]:.1f} cm "
          f"({v.sinkage_rel_diff:.0%}; candidate - reference: 95 % interval {lo:+.0%} to {hi:+.0%})")  # fmt: skip
    print(f"  a sole reached the floor in {v.floor_reached[0]} vs {v.floor_reached[1]} episodes "
          f"(p = {v.floor_p:.3g})")  # fmt: skip
    if v.decision == "accepted" and max(abs(lo), abs(hi)) > cfg.sinkage_rel_tol:
        print(f"  note: a weak pass: the sinkage interval reaches past the {cfg.sinkage_rel_tol:.0%} tolerance; "
              "more episodes would tell")  # fmt: skip
    for r in v.reasons:
        print(f"  - {r}")
    if a.out is not None:
        a.out.write_text(json.dumps({"cfg": asdict(cfg), **asdict(v)}, indent=1))
    return v


if __name__ == "__main__":
    main()
