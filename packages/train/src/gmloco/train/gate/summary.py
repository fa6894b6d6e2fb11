# SPDX-License-Identifier: Apache-2.0
"""Reduce the gate's episode rows to the issue's keys and compare each with its threshold."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gmloco.train.gate.config import GateCfg, GateThresholdsCfg
from gmloco.train.teacher_student.heldout import r2_score

__all__ = ["gate_metrics", "gate_pass"]


def _key(value: float) -> str:
    """Command value as a JSON key: ``0.5``, ``1``, ``-0.5``."""
    return f"{value:g}"


def _mean(values: list[float]) -> float | None:
    """Mean of the finite values; None when there are none (JSON has no NaN)."""
    finite = [v for v in values if math.isfinite(v)]
    return float(np.mean(finite)) if finite else None


def _rows(rows: list[dict[str, Any]], kind: str, material: str, command: tuple[float, ...] | None = None) -> list:
    """Rows of one cell kind and material (and command)."""
    return [
        r
        for r in rows
        if r["cell"].kind == kind
        and r["cell"].material == material
        and (command is None or r["cell"].command == command)
    ]


def gate_metrics(cfg: GateCfg, rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Return the issue's keys from the episode rows of :func:`gmloco.train.gate.rollout.run_cells`.

    ``success_pct``, ``vel_error_mps``, ``heading_drift_deg``: ``{material: {v_x: value}}`` over the forward cells
    ([%], [m/s], [deg], means over episodes); ``yaw_rate_ratio``: ``{material: {w_z: mean achieved / commanded}}``;
    ``circle_dtw_m``: ``{material: mean DTW error}`` [m]; ``swing_apex_cm``: ``{material: mean apex}`` [cm] of the
    ``apex_speed`` forward cells; ``eta_r2_heldout``: pooled R^2 of the held-out cells (None without a decoded eta).
    """
    out: dict[str, Any] = {k: {} for k in ("success_pct", "vel_error_mps", "yaw_rate_ratio", "heading_drift_deg")}
    out |= {"circle_dtw_m": {}, "swing_apex_cm": {}}
    for m in cfg.materials:
        for key in ("success_pct", "vel_error_mps", "heading_drift_deg", "yaw_rate_ratio"):
            out[key][m] = {}
        for v in cfg.speeds:
            sel = _rows(rows, "forward", m, (v, 0.0, 0.0))
            out["success_pct"][m][_key(v)] = 100.0 * float(np.mean([not r["failed"] for r in sel]))
            out["vel_error_mps"][m][_key(v)] = _mean([r["vel_error"] for r in sel])
            out["heading_drift_deg"][m][_key(v)] = _mean([r["drift_deg"] for r in sel])
        for w in cfg.yaw_rates:
            sel = _rows(rows, "yaw", m, (cfg.yaw_forward_speed, 0.0, w))
            out["yaw_rate_ratio"][m][_key(w)] = _mean([r["yaw_rate"] / w for r in sel])
        out["circle_dtw_m"][m] = _mean([r["dtw_m"] for r in _rows(rows, "circle", m)])
        apex = [h for r in _rows(rows, "forward", m, (cfg.apex_speed, 0.0, 0.0)) for h in r["apex_m"]]
        out["swing_apex_cm"][m] = 100.0 * float(np.mean(apex)) if apex else None
    held = [r for r in rows if r["cell"].kind == "held_out" and "eta" in r]
    if held:
        pred = np.concatenate([r["eta"][0] for r in held])
        true = np.concatenate([r["eta"][1] for r in held])
        r2 = r2_score(pred, true)
        out["eta_r2_heldout"] = r2 if math.isfinite(r2) else None
    else:
        out["eta_r2_heldout"] = None
    return out


def _all_within(table: dict[str, dict[str, float | None]], ok: Any) -> bool:
    """Every value of a ``{material: {command: value}}`` table present and ``ok``."""
    values = [v for per in table.values() for v in per.values()]
    return bool(values) and all(v is not None and ok(v) for v in values)


def gate_pass(metrics: dict[str, Any], thresholds: GateThresholdsCfg, materials: tuple[str, ...]) -> dict[str, bool]:
    """Compare every key with its threshold; ``all`` is their conjunction (a missing value fails)."""
    t = thresholds
    apex = metrics["swing_apex_cm"]
    first, last = apex.get(materials[0]), apex.get(materials[-1])
    circles = list(metrics["circle_dtw_m"].values())
    verdict = {
        "success_pct": _all_within(metrics["success_pct"], lambda v: v >= t.success_pct),
        "vel_error_mps": _all_within(metrics["vel_error_mps"], lambda v: v <= t.vel_error_mps),
        "yaw_rate_ratio": _all_within(metrics["yaw_rate_ratio"], lambda v: abs(v - 1.0) <= t.yaw_rate_tolerance),
        "heading_drift_deg": _all_within(metrics["heading_drift_deg"], lambda v: v <= t.heading_drift_deg),
        "circle_dtw_m": bool(circles) and all(v is not None and v <= t.circle_dtw_m for v in circles),
        "swing_apex_cm": first is not None and last is not None and last - first >= t.swing_apex_rise_cm,
        "eta_r2_heldout": metrics["eta_r2_heldout"] is not None and metrics["eta_r2_heldout"] >= t.eta_r2_heldout,
        "gpu_minutes": metrics.get("gpu_minutes") is not None and metrics["gpu_minutes"] <= t.gpu_minutes,
    }
    return verdict | {"all": all(verdict.values())}
