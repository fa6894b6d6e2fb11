# SPDX-License-Identifier: Apache-2.0
"""The mismatch pipeline: contract -> replay -> residuals -> localisation -> attribution -> report dict."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from gmloco.deploy.mismatch.attribution import AttributionCfg, Hypothesis, confirm, decide, screen, second_round
from gmloco.deploy.mismatch.contract import ContractCfg, ContractError, ContractIssue, check_recording
from gmloco.deploy.mismatch.effects import EFFECTS, check_effect_ids
from gmloco.deploy.mismatch.localize import localize
from gmloco.deploy.mismatch.problem import FloorCfg, Problem, effective_samples
from gmloco.deploy.mismatch.recording import Recording
from gmloco.deploy.mismatch.replay import N_CHANNELS, ReplayCfg, Replayer, channel_names
from gmloco.deploy.mismatch.segmentation import (
    MOTION_PHASES,
    PHASES,
    SegmentationCfg,
    motion_phases,
    segment_phases,
)
from gmloco.deploy.mismatch.stages import recording_stage

__all__ = ["AnalysisCfg", "AnalysisResult", "Attribution", "analyze", "attribute"]


@dataclass
class AnalysisCfg:
    """Every setting of one analysis."""

    replay: ReplayCfg = field(default_factory=ReplayCfg)
    """Multiple-shooting replay."""
    floor: FloorCfg = field(default_factory=FloorCfg)
    """Noise floor."""
    attribution: AttributionCfg = field(default_factory=AttributionCfg)
    """Screening, fits and thresholds."""
    contract: ContractCfg = field(default_factory=ContractCfg)
    """Data-contract thresholds."""
    segmentation: SegmentationCfg = field(default_factory=SegmentationCfg)
    """Stance/swing detector."""
    mirror_check: bool = True
    """Also test a left/right-swapped joint map in the simulator (a consistent swap passes the light checks)."""


@dataclass
class AnalysisResult:
    """Report content plus arrays for plots."""

    report: dict
    """JSON-ready report (schema in :mod:`gmloco.deploy.mismatch.report`)."""
    arrays: dict = field(default_factory=dict)
    """Residuals, simulations and regressors for plotting."""


_LR = np.r_[6:12, 0:6, 12:15, 22:29, 15:22]  # left <-> right column swap of legs and arms


def _mirror_error(rec: Recording, cfg: AnalysisCfg) -> ContractIssue | None:
    """Return a joint-map issue if swapping left/right columns fits the simulator far better."""
    n = min(rec.n, int(3.0 / max(rec.dt, 1e-6)))
    short = rec.slice(0, n)
    sw = replace(
        short, **{k: getattr(short, k)[:, _LR] for k in ("q", "dq", "tau_est", "q_cmd", "dq_cmd", "kp", "kd", "tau_ff")}
    )
    e = []
    for r in (short, sw):
        pb = Problem(Replayer(r, cfg.replay), cfg.floor)
        e.append(float(np.mean(pb.resid({}) ** 2)))
    if e[1] < 0.5 * e[0] and e[0] > 3.0:
        return ContractIssue(
            "joint_map",
            "error",
            f"left/right-swapped joint columns fit the simulator {e[0] / e[1]:.1f}x better: the log's joint map mirrors the legs/arms",
            {"energy_as_labelled": e[0], "energy_swapped": e[1]},
        )
    return None


def _phases(
    rec: Recording, rp: Replayer, cfg: SegmentationCfg
) -> tuple[np.ndarray, tuple[str, ...], np.ndarray | None]:
    """Phase codes per sample [N, K], their labels, and the phase column of each output channel.

    A free robot gets foot phases (swing, touchdown, stance, liftoff; ``columns`` None: the channel's foot). A held
    robot touches nothing: each joint channel gets its joint's motion label (hold, low_freq, high_freq) and the IMU
    channels that of the busiest leg or waist joint (column 29).
    """
    if not rec.fixed_base:
        return segment_phases(rp.base({}, np.arange(rec.n)).foot_height, rec.dt, cfg), PHASES, None
    per_joint = motion_phases(rec.q_cmd, rec.dt, cfg)
    codes = np.concatenate([per_joint, per_joint[:, :15].max(axis=1, keepdims=True)], axis=1)
    columns = np.concatenate([np.tile(np.arange(29), 3), np.full(N_CHANNELS - 87, 29)])
    return codes, MOTION_PHASES, columns


def _invalid(issues: list[ContractIssue], rec: Recording | None, t0: float) -> AnalysisResult:
    """Report for input that cannot be analysed: every effect untested, with the reasons."""
    reasons = "; ".join(i.message for i in issues if i.severity == "error")
    return AnalysisResult(
        {
            "verdict": "invalid_input",
            "contract": [i.to_dict() for i in issues],
            "untested": [{"id": e.id, "reason": f"input rejected: {reasons}", "needs": e.excitation} for e in EFFECTS],
            "hypotheses": [],
            "runtime_s": time.time() - t0,
        }
    )


@dataclass
class Attribution:
    """What :func:`attribute` found on one residual problem."""

    y0: np.ndarray
    """Nominal simulation, shape [S, P, N_CHANNELS]."""
    r0: np.ndarray
    """Nominal normalised residual, shape [S, P, N_CHANNELS]."""
    n_eff: float
    """Effective number of independent training residuals."""
    hyps: list[Hypothesis]
    """Screened effects."""
    ranked: list[Hypothesis]
    """Fitted effects, best first."""
    decision: dict
    """Verdict and its evidence (:func:`decide`)."""


def _fit_ticks(say: Callable[[str, float], None], stage: str, lo: float, hi: float, n: int) -> Callable[[], None]:
    """Progress of ``n`` fits between the fractions ``lo`` and ``hi``: announce the stage now, tick per fit."""
    done = [0]
    say(f"{stage} (0/{n})", lo)

    def tick() -> None:
        done[0] += 1
        say(f"{stage} ({done[0]}/{n})", lo + (hi - lo) * done[0] / max(n, 1))

    return tick


def attribute(pb: Problem, cfg: AnalysisCfg, say: Callable[[str, float], None]) -> Attribution:
    """Nominal replay, screening, confirmatory fits (and a second round if unexplained), and the verdict."""
    y0 = pb.simulate({})
    r0 = pb.normalise(y0)
    n_eff = effective_samples(r0[pb.train])
    ids = cfg.attribution.effects
    ncols = sum(e.size for e in EFFECTS if ids is None or e.id in ids)
    done = [0]

    def tick() -> None:
        done[0] += 1
        say("screening effects", 0.1 + 0.5 * done[0] / ncols)

    hyps = screen(pb, r0, y0, n_eff, cfg.attribution, tick)
    n_fits = min(cfg.attribution.top_k, sum(h.testable for h in hyps))
    ranked = confirm(pb, hyps, r0, cfg.attribution, _fit_ticks(say, "confirmatory fits", 0.6, 0.8, n_fits))
    decision = decide(pb, r0, ranked, cfg.attribution)
    if decision["verdict"] == "unexplained" and cfg.attribution.top_k_extra > 0:
        more = second_round(hyps, ranked, cfg.attribution)
        extra = confirm(pb, hyps, r0, cfg.attribution, _fit_ticks(say, "second-round fits", 0.8, 0.9, len(more)), more)
        ranked = sorted(ranked + extra, key=lambda h: (not h.passed, -h.heldout_gain))
        decision = decide(pb, r0, ranked, cfg.attribution)
    return Attribution(y0, r0, n_eff, hyps, ranked, decision)


def analyze(
    rec: Recording, cfg: AnalysisCfg | None = None, progress: Callable[[str, float], None] | None = None
) -> AnalysisResult:
    """Analyse one recording (see the package docstring for the steps).

    Contract errors do not raise: they return an ``invalid_input`` report (joint-map errors are reported as
    such, never as physics).

    Raises:
        ValueError: ``cfg.attribution.effects`` names an effect that is not in the library.
    """
    cfg = cfg or AnalysisCfg()
    if cfg.attribution.effects is not None:
        check_effect_ids(cfg.attribution.effects)
    t0 = time.time()
    say = progress or (lambda msg, frac: None)
    say("contract checks", 0.0)
    try:
        issues = check_recording(rec, cfg.contract)
    except ContractError as exc:
        return _invalid(exc.issues, rec, t0)
    if cfg.mirror_check:
        bad = _mirror_error(rec, cfg)
        if bad is not None:
            return _invalid([*issues, bad], rec, t0)
    say("nominal replay", 0.05)
    rp = Replayer(rec, cfg.replay)
    pb = Problem(rp, cfg.floor)
    if len(pb.starts) < 12 or pb.held.sum() < 3:
        short = ContractIssue(
            "length", "error", f"only {len(pb.starts)} valid shooting segments: record at least ~5 s without gaps"
        )
        return _invalid([*issues, short], rec, t0)
    att = attribute(pb, cfg, say)
    y0, r0, n_eff, hyps, ranked, decision = att.y0, att.r0, att.n_eff, att.hyps, att.ranked, att.decision
    say("localisation", 0.9)
    phases_all, labels, columns = _phases(rec, rp, cfg.segmentation)
    idx = pb.starts[:, None] + rp.offsets[None, :]
    names = channel_names(rec.joint_names)
    loc = localize(r0, names, phases_all[idx], rec.t[idx], n_eff / r0[pb.train].size, labels=labels, columns=columns)
    winner = next((h for h in ranked if h.spec.id == decision["winner"]), None)
    # confirm() sets theta on every ranked hypothesis, so a winner always has a fit.
    params = {winner.spec.id: winner.theta} if winner is not None and winner.theta is not None else {}
    fitted = pb.simulate(params) if params else y0
    from gmloco.deploy.mismatch.report import build_report

    stage = recording_stage(rec)
    report = build_report(
        rec, pb, hyps, ranked, decision, loc, issues, r0, fitted, n_eff, time.time() - t0, {stage} if stage else set()
    )
    arrays = {
        "y": pb.y,
        "y0": y0,
        "y1": fitted,
        "sigma": pb.sigma,
        "names": names,
        "times": rec.t[idx],
        "phases": phases_all[idx],
        "phase_labels": labels,
        "winner": winner,
        "table": loc["table"],
        "held": pb.held,
        "problem": pb,
        "r0": r0,
    }
    say("done", 1.0)
    return AnalysisResult(report, arrays)
