# SPDX-License-Identifier: Apache-2.0
"""Episodes of the G1 on MPM sand and their paper metrics (issue 9): resumable, time-boxed, CPU or CUDA.

One episode = a fresh bed (seeded jitter), the robot dropped onto it in its default pose, a constant command for
``episode_s``: ``straight`` (v_x, 0, 0) or ``circle`` (v_x, 0, v_x / R). Logged at the policy rate (50 Hz): base
pose and velocity, sand force on the feet, sole height. Scored with :mod:`gmloco.eval.metrics.locomotion`:

* failure: base height < 0.2 m above the sand surface, |roll| or |pitch| > pi/4, or the course not finished
  in ``episode_s``. The course is the commanded path (``circular_path``); it counts as finished once the nearest
  commanded sample to the base (searched forwards only) is past ``1 - course_slack`` of the path (a project
  choice: the paper gives no tolerance, and an exact v T lets no lag through).
* velocity tracking error: mean |v_xy - v_cmd| in the yaw frame over alive steps; yaw tracking error: mean
  |w_z - w_cmd| over alive steps; path error: DTW between executed and commanded xy paths (alive part).

Outputs under ``out_dir``: ``episodes.jsonl`` (one line per finished episode; the resume state) and
``summary.json`` (per (material, scenario, speed) and overall).
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from gmloco.eval.metrics.locomotion import (
    FailureCfg,
    circular_path,
    episode_outcome,
    metric_path_error,
    metric_velocity_tracking_error,
    metric_yaw_tracking_error,
    quat_wxyz_to_roll_pitch_yaw,
)
from gmloco.eval.mpm.bed import SandBedCfg
from gmloco.eval.mpm.box_scene import MpmSolverCfg

__all__ = ["EpisodeSpec", "G1EvalCfg", "episode_specs", "load_policy", "run", "run_episode", "score_episode"]

Scenario = Literal["straight", "circle"]


@dataclass(frozen=True)
class G1EvalCfg:
    """The MPM evaluation of one policy."""

    policy_path: str = "artifacts/ppo_rft3d/policy.onnx"
    """Exported policy: gmloco student format (``obs`` + ``history``) or mjlab's actor export (``obs`` only)."""
    out_dir: str = "results/mpm_eval"
    """Output folder."""
    materials: tuple[str, ...] = ("dry_sand",)
    """Media (``gmloco.contact.MATERIAL_PRESETS`` names)."""
    scenarios: tuple[Scenario, ...] = ("straight",)
    """Command scenarios."""
    speeds: tuple[float, ...] = (1.0, 1.5, 2.0, 2.5)
    """Forward-speed commands [m/s]; episode k of a cell uses ``speeds[k % len(speeds)]``."""
    num_episodes: int = 100
    """Episodes per (material, scenario)."""
    episode_s: float = 10.0
    """Episode length = course time limit [s]."""
    circle_radius: float = 2.0
    """Radius of the circular walk [m] (yaw rate = v / R)."""
    course_slack: float = 0.2
    """Fraction of the commanded path that may be left when time runs out and still count as finished [-]."""
    bed_width: float = 0.6
    """Bed width across the path [m] (straight) or margin around the circle (circle) [m]."""
    bed_depth: float = 0.15
    """Bed depth [m]."""
    bed_margin: float = 0.4
    """Bed length beyond the commanded path at each end [m]."""
    solver: MpmSolverCfg = field(default_factory=lambda: MpmSolverCfg(frame_dt=0.01, rigid_substeps=2))
    """MPM numerics (200 Hz physics under 100 Hz MPM frames)."""
    failure: FailureCfg = field(default_factory=FailureCfg)
    """Failure rules."""
    seed: int = 0
    """Seed of the beds."""
    device: str | None = None
    """Warp device."""
    max_minutes: float | None = None
    """Stop (resumable) after this much wall time [min]."""
    resume: bool = True
    """Keep finished episodes in ``episodes.jsonl``; else start fresh."""


@dataclass(frozen=True)
class EpisodeSpec:
    """One episode."""

    material: str
    scenario: Scenario
    speed: float
    index: int

    @property
    def key(self) -> str:
        """Unique id in ``episodes.jsonl``."""
        return f"{self.material}/{self.scenario}/{self.index}"


def episode_specs(cfg: G1EvalCfg) -> list[EpisodeSpec]:
    """All episodes, cell-major."""
    return [
        EpisodeSpec(m, s, float(cfg.speeds[k % len(cfg.speeds)]), k)
        for m in cfg.materials
        for s in cfg.scenarios
        for k in range(cfg.num_episodes)
    ]


def load_policy(path: str | Path) -> Any:
    """Return an object with ``spec`` and ``act(terms)``: the student runner or mjlab's actor export."""
    import onnx

    from gmloco.eval.mpm.g1_scene import MjlabOnnxPolicy, StudentOnnxPolicy

    keys = {p.key for p in onnx.load(str(path), load_external_data=False).metadata_props}
    return StudentOnnxPolicy(path) if "format" in keys else MjlabOnnxPolicy(path)


def _command(spec: EpisodeSpec, cfg: G1EvalCfg) -> tuple[float, float, float]:
    wz = spec.speed / cfg.circle_radius if spec.scenario == "circle" else 0.0
    return (spec.speed, 0.0, wz)


def _bed(spec: EpisodeSpec, cfg: G1EvalCfg, seed: int) -> SandBedCfg:
    """A bed covering the commanded path plus margins."""
    v, _, wz = _command(spec, cfg)
    xy, _ = circular_path(v, wz, cfg.episode_s, 0.05)
    lo, hi = xy.min(axis=0) - cfg.bed_margin, xy.max(axis=0) + cfg.bed_margin
    lo[1], hi[1] = min(lo[1], -0.5 * cfg.bed_width), max(hi[1], 0.5 * cfg.bed_width)
    c, size = 0.5 * (lo + hi), hi - lo
    return SandBedCfg(size_x=float(size[0]), size_y=float(size[1]), depth=cfg.bed_depth, center_x=float(c[0]),
                      center_y=float(c[1]), seed=seed)  # fmt: skip


def run_episode(spec: EpisodeSpec, cfg: G1EvalCfg, policy: Any) -> dict[str, Any]:
    """Simulate one episode; return the per-step log (policy rate) and timings."""
    from gmloco.contact import MATERIAL_PRESETS
    from gmloco.eval.mpm.g1_scene import G1MpmScene, G1MpmSceneCfg

    t0 = time.perf_counter()
    seed = cfg.seed * 100_003 + spec.index
    scene_cfg = G1MpmSceneCfg(bed=_bed(spec, cfg, seed), solver=cfg.solver, command=_command(spec, cfg),
                              device=cfg.device)  # fmt: skip
    if hasattr(policy, "reset"):
        policy.reset()
    scene = G1MpmScene(scene_cfg, MATERIAL_PRESETS[spec.material], policy)
    build_s = time.perf_counter() - t0
    n = round(cfg.episode_s / scene.frame_dt)
    for _ in range(n):
        scene.step()
        q = scene.base_q[-1]
        if not np.all(np.isfinite(q)) or q[2] < cfg.failure.min_base_height:
            break  # fallen: the rest cannot change the outcome
    k = scene.frames_per_policy
    return {
        "dt": scene.frame_dt * k,
        "base_q": np.asarray(scene.base_q)[k - 1 :: k],
        "base_qd": np.asarray(scene.base_qd)[k - 1 :: k],
        "foot_force": np.asarray(scene.foot_force)[k - 1 :: k],
        "sole_z": np.asarray(scene.sole_z)[k - 1 :: k],
        "start_xy": np.asarray(scene.base_q[0][:2]) if scene.base_q else np.zeros(2),
        "robot_mass": scene.robot_mass,
        "particles": scene.particle_count,
        "build_s": build_s,
        "sim_s": scene.wall_time,
        "frames": scene.frame,
    }


def score_episode(spec: EpisodeSpec, cfg: G1EvalCfg, log: dict[str, Any]) -> dict[str, Any]:
    """Paper metrics of one episode log (see the module docstring)."""
    dt, q, qd = log["dt"], log["base_q"], log["base_qd"]
    quat_wxyz = np.concatenate([q[:, 6:7], q[:, 3:6]], axis=1)
    rpy = quat_wxyz_to_roll_pitch_yaw(quat_wxyz)
    v, _, wz = _command(spec, cfg)
    cmd_xy, _ = circular_path(v, wz, cfg.episode_s, dt, start_xy=tuple(log["start_xy"]))
    # progress: nearest commanded sample, searched forwards from the last one (circles revisit points)
    finished_at, idx, window = None, 0, max(1, round(0.5 / dt))
    for t, p in enumerate(q[:, :2]):
        seg = cmd_xy[idx : idx + window]
        idx += int(np.argmin(np.linalg.norm(seg - p, axis=1)))
        if idx >= (1.0 - cfg.course_slack) * (len(cmd_xy) - 1):
            finished_at = (t + 1) * dt
            break
    out = episode_outcome(q[:, 2], rpy[:, 0], rpy[:, 1], dt, finished_at, cfg.failure)
    alive = max(out.alive_steps, 1)
    yaw = rpy[:, 2]
    c, s = np.cos(yaw), np.sin(yaw)
    v_yaw = np.stack([c * qd[:, 0] + s * qd[:, 1], -s * qd[:, 0] + c * qd[:, 1]], axis=1)
    fz = log["foot_force"][:, :, 2].sum(axis=1) if len(log["foot_force"]) else np.zeros(1)
    return {
        "key": spec.key, "material": spec.material, "scenario": spec.scenario, "speed": spec.speed,
        "success": out.success, "reason": out.reason, "alive_s": out.alive_steps * dt,
        "finished_at_s": finished_at,
        "vel_error": metric_velocity_tracking_error(np.tile([v, 0.0], (len(q), 1)), v_yaw, alive),
        "yaw_error": metric_yaw_tracking_error(np.full(len(q), wz), qd[:, 5], alive),
        "path_error": metric_path_error(q[:alive, :2], cmd_xy),
        "support_ratio": float(fz[len(fz) // 2 :].mean() / (log["robot_mass"] * 9.81)),
        "max_sinkage": float(-np.min(log["sole_z"])) if len(log["sole_z"]) else float("nan"),
        "particles": log["particles"], "build_s": log["build_s"], "sim_s": log["sim_s"],
        "frames_per_s": log["frames"] / max(log["sim_s"], 1e-9),
    }  # fmt: skip


def summarize(rows: list[dict[str, Any]]) -> dict[str, float]:
    """Mean metrics per (material, scenario, speed), per (material, scenario) and over all episodes."""
    groups: dict[str, list[dict[str, Any]]] = {"all": rows}
    for r in rows:
        groups.setdefault(f"{r['material']}/{r['scenario']}", []).append(r)
        groups.setdefault(f"{r['material']}/{r['scenario']}/v{r['speed']:g}", []).append(r)
    out: dict[str, float] = {}
    for g, rs in groups.items():
        out[f"{g}/num_episodes"] = float(len(rs))
        out[f"{g}/success_rate"] = float(np.mean([r["success"] for r in rs])) if rs else float("nan")
        for k in ("vel_error", "yaw_error", "path_error", "support_ratio", "max_sinkage", "frames_per_s"):
            vals = [r[k] for r in rs if r[k] is not None and math.isfinite(r[k])]
            out[f"{g}/{k}"] = float(np.mean(vals)) if vals else float("nan")
    return out


def run(cfg: G1EvalCfg) -> tuple[dict[str, float], bool]:
    """Run (or resume) the evaluation; return (summary metrics, complete).

    Writes ``episodes.jsonl`` after every episode and ``summary.json`` at the end of the call. Stops early when
    ``max_minutes`` is reached (complete = False) with every finished episode kept.
    """
    out = Path(cfg.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    log_path = out / "episodes.jsonl"
    if not cfg.resume and log_path.exists():
        log_path.unlink()
    rows = [json.loads(line) for line in log_path.read_text().splitlines()] if log_path.exists() else []
    done = {r["key"] for r in rows}
    policy = load_policy(cfg.policy_path)
    t0 = time.perf_counter()
    complete = True
    for spec in episode_specs(cfg):
        if spec.key in done:
            continue
        if cfg.max_minutes is not None and time.perf_counter() - t0 > 60.0 * cfg.max_minutes:
            complete = False
            break
        row = score_episode(spec, cfg, run_episode(spec, cfg, policy))
        rows.append(row)
        with log_path.open("a") as f:
            f.write(json.dumps(row) + "\n")
    summary = summarize(rows)
    tmp = out / "summary.json.tmp"
    tmp.write_text(json.dumps({"complete": complete, "cfg": _jsonable(asdict(cfg)), "metrics": summary}, indent=1))
    tmp.replace(out / "summary.json")
    return summary, complete


def _jsonable(obj: Any) -> Any:
    return json.loads(json.dumps(obj, default=str))


def smoke_cfg(out_dir: str, policy_path: str) -> G1EvalCfg:
    """CPU smoke: one 1 s straight episode at 1 m/s on a 5 cm-voxel bed."""
    return replace(G1EvalCfg(), out_dir=out_dir, policy_path=policy_path, num_episodes=1, speeds=(1.0,),
                   episode_s=1.0, solver=MpmSolverCfg(voxel_size=0.05, frame_dt=0.01, rigid_substeps=2))  # fmt: skip
