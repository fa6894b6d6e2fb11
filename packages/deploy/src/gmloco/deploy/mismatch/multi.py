# SPDX-License-Identifier: Apache-2.0
"""One diagnosis from several recordings of one robot (``gmloco-mismatch --real a.mcap --real b.mcap``).

Each recording is checked and replayed on its own (its own support, base state, noise floor and held-out split);
their segments are stacked into one :class:`~gmloco.deploy.mismatch.stack.StackedProblem`, so screening, fits and
the verdict run unchanged, and a fitted effect must explain every recording at once. The report adds, per
recording, which effects it excites and where its residual lies.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from gmloco.deploy.mismatch.contract import ContractError, ContractIssue, check_recording
from gmloco.deploy.mismatch.localize import localize
from gmloco.deploy.mismatch.pipeline import (
    AnalysisCfg,
    AnalysisResult,
    Attribution,
    _invalid,
    _mirror_error,
    _phases,
    analyze,
    attribute,
)
from gmloco.deploy.mismatch.problem import Problem
from gmloco.deploy.mismatch.recording import Recording
from gmloco.deploy.mismatch.replay import Replayer, channel_names
from gmloco.deploy.mismatch.stack import StackedProblem, check_same_robot
from gmloco.deploy.mismatch.stages import recording_stage

__all__ = ["analyze_many"]


def _tag(i: int, issue: ContractIssue) -> ContractIssue:
    """The issue, its message prefixed with the recording it concerns."""
    return replace(issue, message=f"recording {i}: {issue.message}")


def _checked(recs: list[Recording], cfg: AnalysisCfg) -> tuple[list[ContractIssue], bool]:
    """Contract findings of every recording and of the set; ``True`` if any is an error."""
    issues = check_same_robot(recs)
    if issues:
        return issues, True
    for i, rec in enumerate(recs):
        try:
            issues += [_tag(i, x) for x in check_recording(rec, cfg.contract)]
        except ContractError as exc:
            return issues + [_tag(i, x) for x in exc.issues], True
        bad = _mirror_error(rec, cfg) if cfg.mirror_check else None
        if bad is not None:
            return [*issues, _tag(i, bad)], True
    return issues, False


def _per_recording(pb: StackedProblem, att: Attribution, cfg: AnalysisCfg, recs: list[Recording]) -> list[dict]:
    """Per recording: what it is, its nominal residual, the effects it excites, and its flagged cells."""
    r0, n_eff, hyps = att.r0, att.n_eff, att.hyps
    src_train = pb.source[pb.train]
    out = []
    for i, (rec, part) in enumerate(zip(recs, pb.parts, strict=True)):
        sel = pb.source == i
        r_i = r0[sel]
        active = float(np.mean(np.broadcast_to(part.weight > 0, r_i.shape)))
        excites = [
            h.spec.id
            for h in hyps
            if h.tol_energy_seg is not None
            and float(np.max(h.tol_energy_seg[src_train == i].sum(axis=0))) >= cfg.attribution.testable_energy
        ]
        phases, labels, columns = _phases(rec, part.rp, cfg.segmentation)
        idx = part.starts[:, None] + part.rp.offsets[None, :]
        loc = localize(r_i, channel_names(rec.joint_names), phases[idx], rec.t[idx], n_eff / r0[pb.train].size,
                       labels=labels, columns=columns)  # fmt: skip
        out.append(
            {
                "index": i,
                "path": rec.meta.get("path"),
                "duration_s": float(rec.t[-1] - rec.t[0]),
                "support": rec.support,
                "base_state": "welded" if rec.fixed_base else "odometry" if rec.has_odometry else "leg_odometry",
                "segments": int(sel.sum()),
                "heldout_segments": int(pb.held[sel].sum()),
                "nominal_energy_ratio": float(np.mean(r_i**2) / max(active, 1e-9)),
                "stage": recording_stage(rec),
                "excites": excites,
                "cells": loc["cells"][:10],
                "windows": loc["windows"],
            }
        )
    return out


def analyze_many(
    recs: list[Recording], cfg: AnalysisCfg | None = None, progress: Callable[[str, float], None] | None = None
) -> AnalysisResult:
    """Analyse several recordings of one robot as one problem; one recording is :func:`analyze` itself.

    Recordings of another robot, joint order or sample rate are a contract error (``invalid_input``). The
    report's ``recordings`` list says which recording excites which effect; each hypothesis lists the
    recordings that excite it (``excited_by``). Its arrays are the stacked problem (``problem``, ``held``), the
    nominal residual (``r0``) and the winning hypothesis (``winner``), as a benchmark's oracle energy needs them.
    """
    from gmloco.deploy.mismatch.report import build_report

    if not recs:
        raise ValueError("analyze_many needs at least one recording")
    if len(recs) == 1:
        return analyze(recs[0], cfg, progress)
    cfg = cfg or AnalysisCfg()
    t0 = time.time()
    say = progress or (lambda msg, frac: None)
    say("contract checks", 0.0)
    issues, bad = _checked(recs, cfg)
    if bad:
        return _invalid(issues, None, t0)
    say("nominal replay", 0.05)
    pb = StackedProblem([Problem(Replayer(rec, cfg.replay), cfg.floor) for rec in recs])
    if len(pb.starts) < 12 or pb.held.sum() < 3:
        short = ContractIssue(
            "length", "error", f"only {len(pb.starts)} valid shooting segments: record at least ~5 s without gaps"
        )
        return _invalid([*issues, short], None, t0)
    att = attribute(pb, cfg, say)
    say("localisation", 0.9)
    per_rec = _per_recording(pb, att, cfg, recs)
    winner = next((h for h in att.ranked if h.spec.id == att.decision["winner"]), None)
    params = {winner.spec.id: winner.theta} if winner is not None and winner.theta is not None else {}
    fitted = pb.simulate(params) if params else att.y0
    cells = sorted(
        [{**c, "recording": r["index"]} for r in per_rec for c in r["cells"]], key=lambda c: -c["energy_ratio"]
    )
    windows = [{**w, "recording": r["index"]} for r in per_rec for w in r["windows"]]
    loc = {"cells": cells, "windows": windows}
    stages = {s for s in map(recording_stage, recs) if s is not None}
    report = build_report(
        recs[0],
        pb,
        att.hyps,
        att.ranked,
        att.decision,
        loc,
        issues,
        att.r0,
        fitted,
        att.n_eff,
        time.time() - t0,
        stages,
    )
    report["recording"] = {"count": len(recs), "segments": len(pb.starts), "heldout_segments": int(pb.held.sum()),
                           "n_eff": att.n_eff}  # fmt: skip
    report["recordings"] = per_rec
    for h in report["hypotheses"]:
        if "rank" in h:
            h["excited_by"] = [r["index"] for r in per_rec if h["id"] in r["excites"]]
    say("done", 1.0)
    return AnalysisResult(report, {"problem": pb, "r0": att.r0, "winner": winner, "held": pb.held})
