# SPDX-License-Identifier: Apache-2.0
"""Reduce the gate's episode rows to the issue's keys and compare each with its threshold."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gmloco.train.gate.config import GateCfg, GateThresholdsCfg
from gmloco.train.teacher_student.heldout import r2_score

__all__ = ["PART_KEYS", "gate_metrics", "gate_pass"]


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


PART_KEYS: dict[str, tuple[str, ...]] = {
    "success": ("success_pct", "vel_error_mps", "heading_drift_deg"),
    "yaw": ("yaw_rate_ratio",),
    "circle": ("circle_dtw_m",),
    "apex": ("swing_apex_cm",),
    "eta": ("eta_r2_heldout",),
}
"""Summary keys of each gate part (``GatePart``)."""


def _short_of_course(row: dict[str, Any]) -> bool:
    """A survivor that never passed the course's end by MPM's rule (rows without ``course_s``: False)."""
    return not row["failed"] and "course_s" in row and row["course_s"] is None


def _forward(cfg: GateCfg, rows: list[dict[str, Any]], out: dict[str, Any]) -> None:
    """Fill ``success_pct``, ``vel_error_mps`` and ``heading_drift_deg`` from the forward cells.

    Beside them, to tell why: ``failures`` (``{material: {v_x: ["<term> at <t> s", ...]}}``, one entry per failed
    episode), ``stance_sink_cm`` (mean depth of a foot in contact below the surface [cm]),
    ``stance_sink_peak_cm`` (the episodes' mean 95th percentile of that depth [cm]) and ``success_course_pct``
    (success by MPM's rule [%]: survived and passed ``1 - course_slack`` of the commanded line within the episode;
    a survivor short of it is listed in ``failures`` as ``course_unfinished``).
    """
    for key in (*PART_KEYS["success"], "failures", "stance_sink_cm", "stance_sink_peak_cm", "success_course_pct"):
        out[key] = {m: {} for m in cfg.materials}
    for m in cfg.materials:
        for v in cfg.speeds:
            sel = _rows(rows, "forward", m, (v, 0.0, 0.0))
            out["failures"][m][_key(v)] = [f"{r['failure']} at {r['fail_s']:.2f} s" for r in sel if r.get("failure")]
            out["failures"][m][_key(v)] += ["course_unfinished" for r in sel if _short_of_course(r)]
            sink = _mean([r["stance_sink_m"] for r in sel if "stance_sink_m" in r])
            out["stance_sink_cm"][m][_key(v)] = None if sink is None else 100.0 * sink
            peak = _mean([r["stance_sink_peak_m"] for r in sel if "stance_sink_peak_m" in r])
            out["stance_sink_peak_cm"][m][_key(v)] = None if peak is None else 100.0 * peak
            out["success_pct"][m][_key(v)] = 100.0 * float(np.mean([not r["failed"] for r in sel]))
            course = [not r["failed"] and r["course_s"] is not None for r in sel if "course_s" in r]
            out["success_course_pct"][m][_key(v)] = 100.0 * float(np.mean(course)) if course else None
            out["vel_error_mps"][m][_key(v)] = _mean([r["vel_error"] for r in sel])
            out["heading_drift_deg"][m][_key(v)] = _mean([r["drift_deg"] for r in sel])


def _held_out(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The held-out cells' rows that carry a decoded eta."""
    return [r for r in rows if r["cell"].kind == "held_out" and "eta" in r]


def _eta_by_material(rows: list[dict[str, Any]]) -> dict[str, dict[str, float]] | None:
    """Per held-out material: the true eta and the decoded eta's mean and standard deviation over its steps.

    Tells a biased estimate (the mean off the truth) from a noisy one (a wide spread) where the pooled R^2 alone
    cannot. None without a decoded eta.
    """
    held = _held_out(rows)
    if not held:
        return None
    out: dict[str, dict[str, float]] = {}
    for m in dict.fromkeys(r["cell"].material for r in held):
        decoded = np.concatenate([r["eta"][0] for r in held if r["cell"].material == m])
        true = np.concatenate([r["eta"][1] for r in held if r["cell"].material == m])
        if decoded.size:
            out[m] = {"true": float(true.mean()), "decoded_mean": float(decoded.mean()),
                      "decoded_std": float(decoded.std())}  # fmt: skip
    return out


def _eta_r2(rows: list[dict[str, Any]]) -> float | None:
    """Pooled R^2 of the decoded eta over the held-out cells (None without a decoded eta)."""
    held = _held_out(rows)
    if not held:
        return None
    r2 = r2_score(np.concatenate([r["eta"][0] for r in held]), np.concatenate([r["eta"][1] for r in held]))
    return r2 if math.isfinite(r2) else None


def _turn_falls(cfg: GateCfg, rows: list[dict[str, Any]]) -> dict[str, Any] | None:
    """Episodes that fell in the yaw and circle cells: ``{"yaw": {material: {w_z: n}}, "circle": {material: n}}``.

    A turning robot that falls has its yaw rate and path measured over the steps it was alive; the fall itself
    fails the key (:func:`gate_pass`), so a short turn before a fall never passes. None when neither part ran.
    """
    if "yaw" not in cfg.parts and "circle" not in cfg.parts:
        return None
    falls: dict[str, Any] = {}
    if "yaw" in cfg.parts:
        falls["yaw"] = {
            m: {_key(w): sum(r["failed"] for r in _rows(rows, "yaw", m, (cfg.yaw_forward_speed, 0.0, w)))
                for w in cfg.yaw_rates}
            for m in cfg.materials
        }  # fmt: skip
    if "circle" in cfg.parts:
        falls["circle"] = {m: sum(r["failed"] for r in _rows(rows, "circle", m)) for m in cfg.materials}
    return falls


def gate_metrics(cfg: GateCfg, rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Return the issue's keys from the episode rows of :func:`gmloco.train.gate.rollout.run_cells`.

    ``success_pct``, ``vel_error_mps``, ``heading_drift_deg``: ``{material: {v_x: value}}`` over the forward cells
    ([%], [m/s], [deg], means over episodes); ``yaw_rate_ratio``: ``{material: {w_z: mean achieved / commanded}}``;
    ``circle_dtw_m``: ``{material: mean DTW error}`` [m]; ``swing_apex_cm``: ``{material: mean apex}`` [cm] of the
    ``apex_speed`` forward cells; ``eta_r2_heldout``: pooled R^2 of the held-out cells (None without a decoded eta);
    ``turn_falls``: the falls of the yaw and circle cells (:func:`_turn_falls`); ``eta_heldout_by_material``: the
    held-out materials' true and decoded eta (:func:`_eta_by_material`). The keys of a part not in ``cfg.parts`` are
    None.
    """
    keys = ("success_pct", "vel_error_mps", "yaw_rate_ratio", "heading_drift_deg", "circle_dtw_m", "swing_apex_cm")
    extra = ("failures", "stance_sink_cm", "stance_sink_peak_cm", "success_course_pct", "turn_falls",
             "eta_heldout_by_material")  # fmt: skip
    out: dict[str, Any] = dict.fromkeys((*keys, "eta_r2_heldout", *extra))
    if "success" in cfg.parts:
        _forward(cfg, rows, out)
    if "yaw" in cfg.parts:
        out["yaw_rate_ratio"] = {
            m: {_key(w): _mean([r["yaw_rate"] / w for r in _rows(rows, "yaw", m, (cfg.yaw_forward_speed, 0.0, w))])
                for w in cfg.yaw_rates}
            for m in cfg.materials
        }  # fmt: skip
    if "circle" in cfg.parts:
        out["circle_dtw_m"] = {m: _mean([r["dtw_m"] for r in _rows(rows, "circle", m)]) for m in cfg.materials}
    out["turn_falls"] = _turn_falls(cfg, rows)
    if "apex" in cfg.parts:
        out["swing_apex_cm"] = {}
        for m in cfg.materials:
            apex = [h for r in _rows(rows, "forward", m, (cfg.apex_speed, 0.0, 0.0)) for h in r["apex_m"]]
            out["swing_apex_cm"][m] = 100.0 * float(np.mean(apex)) if apex else None
    if "eta" in cfg.parts:
        out["eta_r2_heldout"] = _eta_r2(rows)
        out["eta_heldout_by_material"] = _eta_by_material(rows)
    return out


def _all_within(table: dict[str, dict[str, float | None]], ok: Any) -> bool:
    """Every value of a ``{material: {command: value}}`` table present and ``ok``."""
    values = [v for per in table.values() for v in per.values()]
    return bool(values) and all(v is not None and ok(v) for v in values)


def _verdicts(metrics: dict[str, Any], t: GateThresholdsCfg, materials: tuple[str, ...]) -> dict[str, bool]:
    """Compare every key of every part with its threshold (a missing value fails; so does a fall while turning)."""
    apex = metrics["swing_apex_cm"] or {}
    first, last = apex.get(materials[0]), apex.get(materials[-1])
    circles = list((metrics["circle_dtw_m"] or {}).values())
    eta = metrics["eta_r2_heldout"]
    falls = metrics.get("turn_falls") or {}
    yaw_falls = sum(n for per in (falls.get("yaw") or {}).values() for n in per.values())
    circle_falls = sum((falls.get("circle") or {}).values())
    return {
        "success_pct": _all_within(metrics["success_pct"] or {}, lambda v: v >= t.success_pct),
        "vel_error_mps": _all_within(metrics["vel_error_mps"] or {}, lambda v: v <= t.vel_error_mps),
        "yaw_rate_ratio": yaw_falls == 0
        and _all_within(metrics["yaw_rate_ratio"] or {}, lambda v: abs(v - 1.0) <= t.yaw_rate_tolerance),
        "heading_drift_deg": _all_within(metrics["heading_drift_deg"] or {}, lambda v: v <= t.heading_drift_deg),
        "circle_dtw_m": circle_falls == 0
        and bool(circles)
        and all(v is not None and v <= t.circle_dtw_m for v in circles),
        "swing_apex_cm": first is not None and last is not None and last - first >= t.swing_apex_rise_cm,
        "eta_r2_heldout": eta is not None and eta >= t.eta_r2_heldout,
    }


def gate_pass(
    metrics: dict[str, Any],
    thresholds: GateThresholdsCfg,
    materials: tuple[str, ...],
    parts: tuple[str, ...] = tuple(PART_KEYS),
) -> dict[str, bool | None]:
    """Compare every key with its threshold; ``all`` is their conjunction (a missing value fails).

    The keys of a part not in ``parts`` are None (not measured), and ``all`` is then False: a partial run never
    passes the gate.
    """
    verdict: dict[str, bool | None] = dict(_verdicts(metrics, thresholds, materials))
    for part, keys in PART_KEYS.items():
        if part not in parts:
            verdict |= dict.fromkeys(keys)
    minutes = metrics.get("gpu_minutes")
    verdict["gpu_minutes"] = minutes is not None and minutes <= thresholds.gpu_minutes
    return verdict | {"all": all(v is True for v in verdict.values())}
