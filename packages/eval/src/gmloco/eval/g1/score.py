# SPDX-License-Identifier: Apache-2.0
"""Paper metrics of one episode log (:func:`score_episode`) and the sand-window checks behind them.

The metrics are defined in :mod:`gmloco.eval.g1.run`'s docstring; the pure functions live in
:mod:`gmloco.eval.metrics.locomotion`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gmloco.eval.g1.config import EpisodeSpec, G1EvalCfg, command
from gmloco.eval.g1.lanes import window_and_lanes
from gmloco.eval.metrics.locomotion import (
    circular_path,
    course_finished_at,
    episode_outcome,
    metric_heading_error_deg,
    metric_path_error,
    metric_velocity_tracking_error,
    metric_yaw_tracking_error,
    quat_wxyz_to_roll_pitch_yaw,
    swing_clearance,
)
from gmloco.eval.mpm.window import SandWindowCfg, reach_within_window

__all__ = [
    "WINDOW_EXIT_GRACE_S",
    "WINDOW_EXIT_MARGIN_M",
    "heading_turn_deg",
    "layer_stats",
    "reach_fits",
    "score_episode",
    "sole_reach_max",
    "window_exit_cause",
    "window_exit_time",
]


def score_episode(spec: EpisodeSpec, cfg: G1EvalCfg, log: dict[str, Any]) -> dict[str, Any]:
    """Paper metrics of one episode log (see the module docstring)."""
    dt, q, qd = log["dt"], log["base_q"], log["base_qd"]
    quat_wxyz = np.concatenate([q[:, 6:7], q[:, 3:6]], axis=1)
    rpy = quat_wxyz_to_roll_pitch_yaw(quat_wxyz)
    v, _, wz = command(spec, cfg)
    cmd_xy, _ = circular_path(v, wz, cfg.episode_s, dt, start_xy=tuple(log["start_xy"]))
    finished_at = course_finished_at(q[:, :2], cmd_xy, dt, cfg.course_slack)
    height = np.asarray(log.get("base_height", q[:, 2]))
    out = episode_outcome(height, rpy[:, 0], rpy[:, 1], dt, finished_at, cfg.failure)
    alive = max(out.alive_steps, 1)
    yaw = rpy[:, 2]
    c, s = np.cos(yaw), np.sin(yaw)
    v_yaw = np.stack([c * qd[:, 0] + s * qd[:, 1], -s * qd[:, 0] + c * qd[:, 1]], axis=1)
    fz = log["foot_force"][:, :, 2].sum(axis=1) if len(log["foot_force"]) else np.zeros(1)
    sink = np.asarray(log["sinkage"])[:alive]
    swing = swing_clearance(-np.asarray(log["foot_sinkage"]), np.asarray(log["foot_force"])[..., 2], alive)
    eta = np.asarray(log.get("eta", np.full(len(q), np.nan)), dtype=float)[:alive]
    exit_s = window_exit_time(log.get("sole_out"), dt, alive)
    behind, ahead, side = sole_reach_max(log.get("sole_reach"), alive)
    cause = window_exit_cause(log.get("sole_reach"), exit_s, dt, window_and_lanes([spec], cfg)[0])
    early = exit_s is not None and exit_s < out.alive_steps * dt - WINDOW_EXIT_GRACE_S
    return {
        "key": spec.key, "terrain": spec.terrain, "scenario": spec.scenario, "speed": spec.speed,
        "success": out.success, "reason": out.reason, "alive_s": out.alive_steps * dt,
        "finished_at_s": finished_at,
        "vel_error": metric_velocity_tracking_error(np.tile([v, 0.0], (len(q), 1)), v_yaw, alive),
        "heading_error_deg": metric_heading_error_deg(yaw, wz, dt, alive),
        "yaw_error": metric_yaw_tracking_error(np.full(len(q), wz), qd[:, 5], alive),
        "path_error": metric_path_error(q[:alive, :2], cmd_xy),
        "support_ratio": float(fz[len(fz) // 2 :].mean() / (log["robot_mass"] * 9.81)),
        "max_sinkage": float(np.max(sink)) if len(sink) else float("nan"),
        "mean_sinkage": float(np.mean(sink)) if len(sink) else float("nan"),
        "swing_apex": swing.apex, "swing_lift": swing.lift, "swings": swing.swings,
        "eta_mean": float(np.mean(eta)) if np.isfinite(eta).any() else float("nan"),
        "layers": layer_stats(log, alive),
        # a sole that needed sand stood outside its sand window (no particles there): the window was too small
        "window_exit_s": exit_s, "window_exit_early": early, "window_exit_cause": cause,
        # the window is a box of the grid's axes: a robot that turned can step out of it within its reach
        "window_exit_turn": early and cause == "turn", "heading_turn_deg": heading_turn_deg(yaw, alive),
        # how much window the soles needed: their reach from the pelvis (yaw frame) while near or in the sand
        "sole_behind_m": behind, "sole_ahead_m": ahead, "sole_side_m": side,
        # a sole reached the rigid floor under the sand (the soles stand on it): the bed was too shallow there
        "floor_reached": bool(len(sink) and np.max(sink) >= log.get("depth", math.inf) - 0.005),
        "particles": log["particles"], "batch_size": log.get("batch_size", 1), "build_s": log["build_s"],
        "sim_s": log["sim_s"], "frames_per_s": log["frames"] / max(log["sim_s"], 1e-9),
        # the scene's frame at the episode's end and the wall seconds since its first frame, host work included
        # (``sim_s`` is the scene's stepping time: ``G1MpmScene.step`` and, since the square-window runs, every wait for the
        # frames in flight; before, the waits of the grid-capacity checks went uncounted and rates read ~8 % high)
        "end_frame": log["frames"], "elapsed_s": log.get("elapsed_s"),
    }  # fmt: skip


WINDOW_EXIT_GRACE_S = 0.25
"""A sole leaving the sand window this close to an episode's end (the fall under way) does not flag it [s]."""


def window_exit_time(sole_out: Any, dt: float, alive: int) -> float | None:
    """First time [s] a sole corner that needed sand lay outside the window (``soles_outside``); None if never.

    ``sole_out``: per-sample counts ([T] or [T, 1]); None for logs written before the check existed.
    """
    if sole_out is None:
        return None
    counts = np.asarray(sole_out, dtype=float).reshape(len(sole_out), -1).sum(axis=1)[:alive]
    hit = np.flatnonzero(counts > 0)
    return float(hit[0] * dt) if len(hit) else None


WINDOW_EXIT_MARGIN_M = 0.02
"""Reach this close to the window's edge counts as beyond it (the window moves in whole particle columns) [m]."""


def window_exit_cause(reach: Any, exit_s: float | None, dt: float, window: SandWindowCfg) -> str | None:
    """Why the soles first left the sand window, from their reach at that sample (``sole_reach``, pelvis yaw frame).

    ``"turn"``: they lay within the window's extent measured along the robot's heading (behind, ahead, beside the
    pelvis, less ``WINDOW_EXIT_MARGIN_M``; for a turning window under its worst heading lag), so the exit came from
    the robot turning away from a window that does not turn with it. ``"reach"``: they reached beyond that extent
    (the window is too short or narrow, or a static bed). None without an exit or without a reach log (older runs).
    """
    if reach is None or exit_s is None:
        return None
    arr = np.asarray(reach, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 3 or not len(arr):
        return None
    k = min(round(exit_s / dt), len(arr) - 1)
    if not np.isfinite(arr[k]).all():
        return None
    return "turn" if window.moving and reach_fits(tuple(arr[k]), window) else "reach"


def reach_fits(reach: tuple[float, float, float], window: SandWindowCfg) -> bool:
    """Whether the soles' reach (behind, ahead, beside the pelvis) [m] lies within the window's extent.

    Measured along the robot's heading, less ``WINDOW_EXIT_MARGIN_M`` on every side; a turning window may lag the
    heading by its ``turn_step`` (``window.reach_within_window``).
    """
    return reach_within_window(window, (float(reach[0]), float(reach[1]), float(reach[2])), WINDOW_EXIT_MARGIN_M)


def heading_turn_deg(yaw: np.ndarray, alive: int) -> float:
    """Largest turn of the heading away from its start over the alive samples [deg] (yaw [rad], wrapped)."""
    yaw = np.asarray(yaw, dtype=float)[: max(alive, 1)]
    if not len(yaw):
        return math.nan
    turn = np.angle(np.exp(1j * (yaw - yaw[0])))
    return float(np.degrees(np.max(np.abs(turn))))


def sole_reach_max(reach: Any, alive: int) -> tuple[float, float, float]:
    """Largest reach of the soles behind / ahead of / beside the pelvis over the alive samples [m] (``sole_reach``).

    ``reach``: per-sample [T, 3]; NaN entries (soles in the air) are skipped; NaNs when absent (older logs).
    """
    arr = None if reach is None else np.asarray(reach, dtype=float)
    if arr is None or arr.ndim != 2 or arr.shape[1] != 3 or not np.isfinite(arr[:alive]).any():
        return math.nan, math.nan, math.nan
    b, a, s = np.nanmax(arr[:alive], axis=0)
    return float(b), float(a), float(s)


def layer_stats(log: dict[str, Any], alive: int) -> list[dict[str, Any]] | None:
    """Per medium of a layered course (``transition``): decoded eta and swings while the pelvis was over it.

    None for single-medium terrains. Each entry: ``medium``, ``steps`` (alive policy steps over it), ``eta_mean``,
    ``swing_apex`` / ``swing_lift`` [m] and ``swings`` (swings completed within one stretch over it; a swing that
    crosses a boundary counts for neither side), NaN where there are none.
    """
    from gmloco.eval.mpm.window_terrain import terrain_layer

    terrain = log.get("terrain_cfg")
    if terrain is None or len(terrain.materials) < 2:
        return None
    x = np.asarray(log["base_q"])[:alive, 0]
    layer = terrain_layer(terrain, x)
    height = -np.asarray(log["foot_sinkage"])[:alive]
    load = np.asarray(log["foot_force"])[:alive, :, 2]
    eta = np.asarray(log.get("eta", np.full(alive, np.nan)), dtype=float)[:alive]
    out = []
    for k, medium in enumerate(terrain.materials):
        on = layer == k
        runs = _runs(on)
        swings = [swing_clearance(height[a:b], load[a:b]) for a, b in runs]
        finite = eta[on][np.isfinite(eta[on])]
        out.append({"medium": medium, "steps": int(on.sum()), "swings": sum(sw.swings for sw in swings),
                    "eta_mean": float(finite.mean()) if len(finite) else float("nan"),
                    "swing_apex": _pooled(swings, "apex"), "swing_lift": _pooled(swings, "lift")})  # fmt: skip
    return out


def _pooled(parts: list[Any], key: str) -> float:
    """Swing-weighted mean of ``key`` over ``SwingClearance`` parts with a finite value (NaN if none)."""
    pairs = [(getattr(p, key), p.swings) for p in parts if p.swings and math.isfinite(getattr(p, key))]
    total = sum(w for _, w in pairs)
    return sum(v * w for v, w in pairs) / total if total else float("nan")


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, end) of every run of True in ``mask``."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist(), strict=True))
