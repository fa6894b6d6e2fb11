# SPDX-License-Identifier: Apache-2.0
"""The report: ``report.json`` (stable schema), ``report.md`` with plots, and the fitted config patch.

``report.json`` schema (``schema``: ``gmloco.mismatch_report/1``; keys are only ever added):

* ``verdict``: ``no_mismatch`` | ``explained`` | ``unexplained`` | ``invalid_input``.
* ``winner``: effect id (vocabulary in :mod:`gmloco.deploy.mismatch.effects`) when ``explained``, else null.
* ``nearest``: when ``unexplained``, the best passing library effect that nonetheless left a held-out residual
  above the floor (it absorbs part of an out-of-library effect), else null.
* ``contract``: list of ``{check, severity, message, detail}`` (joint map, units, time base, gaps, length).
* ``recording``: ``{duration_s, rate_hz, support: free|gantry|fixed, base_state: odometry|leg_odometry|welded,
  segments, n_eff}``.
* ``noise_floor``: ``{source, per_signal: {q, dq, tau_est, gyro, acc}}`` (median sigma per signal, SI units).
* ``mismatch``: ``{nominal_energy_ratio, residual_ratio, explained_fraction, cells: [...], windows: [...]}``
  (``residual_ratio``: held-out residual energy per element left by the best passing effect, floor = 1); a cell is
  ``{signal, joint, phase, energy_ratio, q_fdr, n}``, a window ``{signal, t: [t0, t1], energy_ratio, q_fdr}``.
* ``hypotheses``: ranked list, each ``{id, rank, testable, dbic_screen, confirmed, dbic, heldout_gain,
  heldout_gain_lo, heldout_gain_lo_signals, p_boot, passed, corr_max, weight, params: {name: {value, ci95, unit}}, confusables, explanation}``;
  followed by ``{id: "none"}`` and ``{id: "unexplained"}`` entries with their weights.
* ``untested``: ``[{id, reason, needs}]`` effects this recording cannot test, and what would make them testable.
* ``before_after``: held-out ``{nrmse_nominal, nrmse_fitted}`` per signal group.
* ``config_patch``: ``{effect_id: {param: value}}`` for the simulator
  (``Replayer.simulate(effects.params_from_patch(patch), starts)`` replays with it).
* ``runtime_s``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.mismatch.effects import EffectSpec
from gmloco.deploy.mismatch.replay import CHANNEL_GROUPS
from gmloco.deploy.mismatch.stages import STAGES, stage_to_record

__all__ = ["SCHEMA", "build_report", "write_report"]

SCHEMA = "gmloco.mismatch_report/1"
"""Report schema id."""


def _params(spec: EffectSpec, theta: np.ndarray, ci: np.ndarray | None) -> dict:
    """Named parameter values with units and intervals."""
    out = {}
    units = [p.unit for p in spec.params for _ in range(p.size)]
    for i, lab in enumerate(spec.labels()):
        out[lab] = {"value": float(theta[i]), "unit": units[i]}
        if ci is not None:
            out[lab]["ci95"] = [float(ci[i, 0]), float(ci[i, 1])]
    return out


def _explain(h: Any) -> str:
    """Templated explanation from the effect metadata and the evidence numbers."""
    return (
        f"{h.spec.title}: {h.spec.model} Fitted on training segments, it removes {100 * h.heldout_gain:.1f}% of the "
        f"held-out residual energy (block-bootstrap p = {h.p_boot:.3g}, Delta-BIC_neff = {h.dbic:.1f}). "
        f"Expected signature: {h.spec.signature}"
    )


def _group_nrmse(pb: Any, sim: np.ndarray) -> dict[str, float]:
    """Held-out RMSE / std(real) per signal group the residual uses.

    Excluded groups (a missing ``tau_est``, a derived accelerometer) are left out.
    """
    out, c = {}, 0
    y = pb.y[pb.held]
    for g, w in CHANNEL_GROUPS:
        sl = slice(c, c + w)
        c += w
        if not np.any(pb.weight[..., sl] > 0):
            continue
        err = np.sqrt(np.mean((y[..., sl] - sim[pb.held][..., sl]) ** 2))
        out[g] = float(err / max(np.std(y[..., sl]), 1e-12))
    return out


def _untested(h: Any, fixed: bool, done_stages: set[str]) -> dict:
    """Why an effect could not be tested here, and the protocol stage to record for it."""
    stage = stage_to_record(h.spec.id, done_stages)
    why = (
        "the pelvis is held and touches nothing"
        if h.spec.ground and fixed
        else "a tolerance-sized change stays below the noise floor on this recording"
    )
    return {
        "id": h.spec.id,
        "reason": f"untestable here: record stage {stage} ({STAGES[stage]}); {why}",
        "stage": stage,
        "record": f"python -m gmloco.deploy.mismatch.benchmark.make_recording --stage {stage}",
        "needs": h.spec.excitation,
    }


def build_report(
    rec: Any,
    pb: Any,
    hyps: list,
    ranked: list,
    decision: dict,
    loc: dict,
    issues: list,
    r0: np.ndarray,
    fitted: np.ndarray,
    n_eff: float,
    runtime: float,
    done_stages: set[str] | None = None,
) -> dict:
    """Assemble the report dict; ``done_stages`` are the protocol stages the recordings already are."""
    done_stages = done_stages if done_stages is not None else set()
    confirmed = {h.spec.id for h in ranked}
    order = ranked + sorted([h for h in hyps if h.spec.id not in confirmed], key=lambda h: -h.dbic_lin)
    bics = np.array([h.dbic if h.spec.id in confirmed else -np.inf for h in order] + [0.0])
    w = np.exp(0.5 * (bics - bics.max()))
    w /= w.sum()
    hyp_out = []
    for rank, h in enumerate(order, 1):
        e = {
            "id": h.spec.id,
            "rank": rank,
            "testable": h.testable,
            "dbic_screen": float(h.dbic_lin),
            "confirmed": h.spec.id in confirmed,
            "weight": float(w[rank - 1]),
        }
        if h.spec.id in confirmed:
            e.update(
                dbic=float(h.dbic),
                heldout_gain=h.heldout_gain,
                heldout_gain_lo=float(h.gain_lo),
                heldout_gain_lo_signals=float(h.gain_lo_signals),
                p_boot=h.p_boot,
                passed=h.passed,
                corr_max=h.corr_max,
            )
            e["params"] = _params(h.spec, h.theta, h.ci)
            e["explanation"] = _explain(h)
        else:
            e["params"] = _params(h.spec, h.theta_lin, None)
        e["confusables"] = list(h.spec.confusables)
        hyp_out.append(e)
    hyp_out.append({"id": "none", "weight": float(w[-1])})
    hyp_out.append(
        {
            "id": "unexplained",
            "residual_share": 1.0 - decision["explained_fraction"] if decision["verdict"] != "no_mismatch" else 0.0,
        }
    )
    win = next((h for h in ranked if h.spec.id == decision["winner"]), None)
    c, floor = 0, {}
    for g, wd in CHANNEL_GROUPS:
        floor[g] = float(np.median(pb.sigma[..., c : c + wd]))
        c += wd
    return {
        "schema": SCHEMA,
        "verdict": decision["verdict"],
        "winner": decision["winner"],
        "nearest": decision.get("nearest"),
        "contract": [i.to_dict() for i in issues],
        "recording": {
            "duration_s": float(rec.t[-1] - rec.t[0]),
            "rate_hz": 1.0 / rec.dt,
            "support": rec.support,
            "base_state": "welded" if rec.fixed_base else "odometry" if rec.has_odometry else "leg_odometry",
            "segments": len(pb.starts),
            "heldout_segments": int(pb.held.sum()),
            "n_eff": n_eff,
        },
        "noise_floor": {
            "source": "measurement noise (second differences) + model floor calibrated on null benchmark episodes",
            "per_signal": floor,
        },
        "mismatch": {
            "nominal_energy_ratio": decision["nominal_energy_ratio"],
            "residual_ratio": decision.get("residual_ratio"),
            "explained_fraction": decision["explained_fraction"],
            "cells": loc["cells"],
            "windows": loc["windows"],
        },
        "hypotheses": hyp_out,
        "untested": [_untested(h, pb.fixed, done_stages) for h in hyps if not h.testable],
        "before_after": {
            "heldout": {
                # r0 carries the group-balance weights: divide them out to recover the nominal simulation
                "nrmse_nominal": _group_nrmse(
                    pb, pb.y - np.divide(r0, pb.weight, out=np.zeros_like(r0), where=pb.weight > 0) * pb.sigma
                ),
                "nrmse_fitted": _group_nrmse(pb, fitted),
            }
        },
        "config_patch": {win.spec.id: {k: v["value"] for k, v in _params(win.spec, win.theta, None).items()}}
        if win is not None
        else {},
        "runtime_s": runtime,
    }


def write_report(result: Any, out: Path, plots: bool = True) -> list[Path]:
    """Write ``report.json``, ``config_patch.json``, ``report.md`` and plots into ``out``; return the paths.

    The plots need one recording's per-channel arrays (``names``); a diagnosis over several recordings has none.
    """
    out.mkdir(parents=True, exist_ok=True)
    rep = dict(result.report)
    files = []
    if plots and "names" in result.arrays:
        from gmloco.deploy.mismatch.plots import make_plots

        rep["plots"] = [p.name for p in make_plots(result, out)]
    (out / "report.json").write_text(json.dumps(rep, indent=2, default=float))
    (out / "config_patch.json").write_text(json.dumps(rep.get("config_patch", {}), indent=2))
    (out / "report.md").write_text(_markdown(rep))
    files += [out / "report.json", out / "config_patch.json", out / "report.md"]
    return files


def _markdown(r: dict) -> str:
    """Human-readable summary of a report dict."""
    lines = [
        f"# Sim-vs-real mismatch report\n\n**Verdict: `{r['verdict']}`**"
        + (f" — winner `{r['winner']}`" if r.get("winner") else "")
        + "\n"
    ]
    for c in r.get("contract", []):
        lines.append(f"- contract [{c['severity']}] {c['check']}: {c['message']}")
    if "mismatch" in r:
        m = r["mismatch"]
        lines.append(
            f"\nNominal residual energy / floor: {m['nominal_energy_ratio']:.2f}; explained fraction: {m['explained_fraction']:.2f}\n"
        )
        lines.append("## Where\n\n| signal | joint | phase | energy ratio | q (FDR) |\n|---|---|---|---|---|")
        lines += [
            f"| {c['signal']} | {c['joint']} | {c['phase']} | {c['energy_ratio']:.2f} | {c['q_fdr']:.2g} |"
            for c in m["cells"][:15]
        ]
    lines.append(
        "\n## Hypotheses\n\n| rank | id | dBIC (screen) | dBIC (fit) | held-out gain | p | passed | params |\n|---|---|---|---|---|---|---|---|"
    )
    for h in r.get("hypotheses", []):
        if "rank" not in h:
            continue
        ps = ", ".join(
            f"{k}={v['value']:.4g}" + (f" [{v['ci95'][0]:.3g}, {v['ci95'][1]:.3g}]" if "ci95" in v else "")
            for k, v in list(h["params"].items())[:4]
        )
        lines.append(
            f"| {h['rank']} | `{h['id']}` | {h['dbic_screen']:.1f} | {h.get('dbic', float('nan')):.1f} | {h.get('heldout_gain', float('nan')):.3f} | {h.get('p_boot', float('nan')):.3g} | {h.get('passed', '')} | {ps} |"
        )
    if r.get("untested"):
        lines.append("\n## Could not be tested\n")
        lines += [f"- `{u['id']}`: {u['reason']}. Needs: {u['needs']}" for u in r["untested"]]
    if "before_after" in r:
        ba = r["before_after"]["heldout"]
        lines.append("\n## Held-out before/after (NRMSE)\n\n| signal | nominal | fitted |\n|---|---|---|")
        lines += [f"| {g} | {ba['nrmse_nominal'][g]:.3f} | {ba['nrmse_fitted'][g]:.3f} |" for g in ba["nrmse_nominal"]]
    for p in r.get("plots", []):
        lines.append(f"\n![{p}]({p})")
    return "\n".join(lines) + "\n"
