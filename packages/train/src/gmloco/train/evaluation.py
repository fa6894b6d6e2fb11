# SPDX-License-Identifier: Apache-2.0
"""Roll out an exported ONNX policy (onnxruntime) in the granular training simulator and score it.

Every env is one cell (material, commanded forward speed, repeat). An env fails when its pelvis is less
than 0.2 m above the sand or |roll| or |pitch| exceeds pi/4 before ``duration_s`` (GM-Loco metrics); the
first episode of each env counts. Tracking errors average over the steps an env is alive:
``vel_error`` = |v_xy - v_cmd| [m/s] in the yaw frame, ``yaw_rate_error`` = |w_z - w_cmd| [rad/s].

With ``EvalCfg.record_dir`` set, the first env of every (material, speed) cell is also recorded in the project's
MCAP log schema (:mod:`gmloco.train.recording`), one file per cell, until it fails or the episode ends.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch

import gmloco.contact as gc
from gmloco.train.config import ContactModelName, TerrainName
from gmloco.train.evaluation_cells import MaterialCellsCfg, RolloutCriteriaCfg
from gmloco.train.mdp.commands import hold_twist

__all__ = ["EvalCfg", "MaterialCellsCfg", "RolloutCriteriaCfg", "evaluate_policy"]


@dataclass
class EvalCfg(MaterialCellsCfg):
    """Evaluation of one ONNX policy in the granular simulator."""

    policy_path: str = "runs/train/ppo_rft3d/policy.onnx"
    """Exported policy (``gmloco.train`` export: metadata gives history length and action scale)."""
    contact_model: ContactModelName | None = None
    """Contact model of the simulator; None: the one in the policy metadata (else rft3d)."""
    terrain: TerrainName = "flat"
    """Sand terrain."""
    device: str = "cpu"
    """Torch / Warp device."""
    seed: int = 0
    """Env seed."""
    out_path: str | None = None
    """If set, write the metrics as JSON here."""
    record_dir: str | None = None
    """If set, record env 0 of each (material, speed) cell to ``<record_dir>/g1_<label>_<material>_v<speed>.mcap``
    (:mod:`gmloco.train.recording`; existing files are not overwritten)."""
    record_label: str | None = None
    """Policy name in the recordings' ``controller = "policy:<label>"``; None: the ONNX ``run_path`` metadata."""
    record_notes: str = ""
    """Free text for the recordings' run metadata (e.g. how far the policy is validated)."""


def _read_metadata(path: str) -> dict[str, str]:
    """Return the ONNX model's metadata properties."""
    import onnx

    return {p.key: p.value for p in onnx.load(path, load_external_data=False).metadata_props}


def _build_env(cfg: EvalCfg, meta: dict[str, str], num_envs: int) -> Any:
    """Build the play-mode env matching the policy's observation layout."""
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.managers.termination_manager import TerminationTermCfg

    from gmloco.train import mdp
    from gmloco.train.tasks.g1_granular import g1_granular_task, make_g1_granular_env_cfg

    model = cfg.contact_model or meta.get("contact_model", "rft3d")
    task = g1_granular_task(model, cfg.terrain, play=True)  # type: ignore[arg-type]
    task = replace(task, terrain=replace(task.terrain, floor=cfg.floor), command_curriculum=False)
    task.policy_history_length = int(meta.get("observation_history_length", 1))
    task.action_scale = float(meta.get("action_scale", task.action_scale))
    task.episode_length_s = cfg.duration_s + 1.0
    env_cfg = make_g1_granular_env_cfg(task, num_envs)
    env_cfg.seed = cfg.seed
    env_cfg.terminations = {
        "base_too_low": TerminationTermCfg(func=mdp.base_height_below, params={"min_height": cfg.min_base_height}),
        "tilt": TerminationTermCfg(func=mdp.roll_pitch_exceeds, params={"limit": cfg.max_tilt}),
    }
    twist = env_cfg.commands["twist"]
    twist.resampling_time_range = (1.0e9, 1.0e9)
    twist.rel_standing_envs, twist.rel_heading_envs, twist.heading_command = 0.0, 0.0, False
    twist.rel_world_envs, twist.rel_forward_envs, twist.ranges.heading = 0.0, 0.0, None
    return ManagerBasedRlEnv(cfg=env_cfg, device=cfg.device)


def _cells(cfg: EvalCfg) -> list[tuple[str, float]]:
    """Per-env (material, speed), material-major."""
    return [(m, s) for m in cfg.materials for s in cfg.speeds for _ in range(cfg.repeats)]


def _pin_cells(env: Any, cells: list[tuple[str, float]]) -> torch.Tensor:
    """Fix each env's material and command; return the commands [W, 3]."""
    sand = env.sand
    presets = [gc.MATERIAL_PRESETS[m] for m, _ in cells]
    as_t = lambda vals: torch.tensor(vals, dtype=torch.float32, device=env.device)  # noqa: E731
    if sand.materials is not None:
        sand.materials.pin(
            as_t([p.rho_c for p in presets]), as_t([p.mu_int for p in presets]), as_t([p.mu_surf for p in presets])
        )
    return as_t([[s, 0.0, 0.0] for _, s in cells])


def _make_recorders(cfg: EvalCfg, env: Any, meta: dict[str, str], cells: list[tuple[str, float]]) -> list[Any]:
    """One :class:`~gmloco.train.recording.EnvRecorder` per (material, speed) cell, on the cell's first env."""
    from gmloco.train.recording import (
        EnvRecorder,
        RecordingCfg,
        policy_label,
        policy_run_metadata,
        recording_file_name,
    )

    assert cfg.record_dir is not None
    label = cfg.record_label or policy_label(cfg.policy_path, meta)
    model = cfg.contact_model or meta.get("contact_model", "rft3d")
    recorders = []
    for m, s in dict.fromkeys(cells):
        k = cells.index((m, s))
        metadata = policy_run_metadata(
            policy_path=cfg.policy_path,
            onnx_meta=meta,
            material=m,
            contact_model=model,
            terrain=cfg.terrain,
            control_rate_hz=1.0 / env.step_dt,
            label=label,
            notes=cfg.record_notes,
            extra={
                "command": {"lin_vel_x": s, "lin_vel_y": 0.0, "ang_vel_z": 0.0},
                "duration_s": cfg.duration_s,
                "env_index": k,
                "num_envs": env.num_envs,
                "seed": cfg.seed,
                "physics_dt": env.physics_dt,
                "failure": {"min_base_height": cfg.min_base_height, "max_tilt": cfg.max_tilt},
                "floor": {"enabled": cfg.floor.enabled, "depth_range": list(cfg.floor.depth_range)},
            },
        )
        path = Path(cfg.record_dir) / recording_file_name(label, m, s)
        recorders.append(EnvRecorder(env, path, metadata, RecordingCfg(env_index=k)))
    return recorders


def tracking_stats(num_envs: int, device: Any) -> dict[str, torch.Tensor]:
    """Zeroed accumulators of :func:`accumulate_tracking`: alive ``steps``, ``vel_err`` and ``yaw_err`` sums."""
    return {k: torch.zeros(num_envs, device=device) for k in ("steps", "vel_err", "yaw_err")}


def accumulate_tracking(stats: dict[str, torch.Tensor], data: Any, commands: torch.Tensor, alive: torch.Tensor) -> None:
    """Add one step of the alive envs: |v_xy - v_cmd| in the yaw frame [m/s] and |w_z - w_cmd| [rad/s].

    Args:
        stats: Accumulators from :func:`tracking_stats` (updated in place).
        data: The robot's mjlab entity data (root pose and velocities, world frame).
        commands: Commanded (v_x, v_y, w_z) per env [m/s, m/s, rad/s], [N, 3].
        alive: Envs that have not failed yet, [N] bool.
    """
    from mjlab.utils.lab_api.math import quat_apply_inverse, yaw_quat

    v_yaw = quat_apply_inverse(yaw_quat(data.root_link_quat_w), data.root_link_lin_vel_w)
    stats["steps"] += alive.float()
    stats["vel_err"] += alive * torch.linalg.vector_norm(v_yaw[:, :2] - commands[:, :2], dim=1)
    stats["yaw_err"] += alive * (data.root_link_ang_vel_w[:, 2] - commands[:, 2]).abs()


def _rollout(
    env: Any, session: Any, commands: torch.Tensor, steps: int, recorders: list[Any] | None = None
) -> dict[str, np.ndarray]:
    """Run the policy; return per-env alive steps, summed velocity and yaw-rate errors, failure flags."""
    term = env.command_manager.get_term("twist")
    env.reset()
    # Commands are never resampled (resampling time 1e9 s); backfill the history with the fixed command.
    hold_twist(term, commands)
    n = env.num_envs
    obs = env.observation_manager.compute(update_history=True, env_ids=torch.arange(n, device=env.device))
    alive = torch.ones(n, dtype=torch.bool, device=env.device)
    stats = tracking_stats(n, env.device)
    name = session.get_inputs()[0].name
    robot = env.scene["robot"]
    for _ in range(steps):
        actor_obs = obs["actor"].cpu().numpy().astype(np.float32)
        # mjlab exports a batch-1 graph (no dynamic axes): one call per env.
        action = np.concatenate([session.run(None, {name: actor_obs[i : i + 1]})[0] for i in range(n)])
        for rec in recorders or ():
            rec.before_step(actor_obs, action)
        obs, _, terminated, _, _ = env.step(torch.as_tensor(action, device=env.device))
        for rec in recorders or ():
            rec.after_step(terminated)
        alive &= ~terminated
        accumulate_tracking(stats, robot.data, commands, alive)
    out = {k: v.cpu().numpy() for k, v in stats.items()}
    out["failed"] = (~alive).cpu().numpy()
    return out


def _summarize(cells: list[tuple[str, float]], raw: dict[str, np.ndarray]) -> dict[str, float]:
    """Aggregate per (material, speed) cell and overall."""
    metrics: dict[str, float] = {}
    groups: dict[str, np.ndarray] = {"all": np.ones(len(cells), dtype=bool)}
    for m, s in dict.fromkeys(cells):
        groups[f"{m}/v{s:g}"] = np.array([c == (m, s) for c in cells])
    steps = np.maximum(raw["steps"], 1.0)
    for key, mask in groups.items():
        metrics[f"{key}/success_rate"] = float(np.mean(~raw["failed"][mask]))
        metrics[f"{key}/vel_error"] = float(np.mean(raw["vel_err"][mask] / steps[mask]))
        metrics[f"{key}/yaw_rate_error"] = float(np.mean(raw["yaw_err"][mask] / steps[mask]))
        metrics[f"{key}/num_envs"] = float(mask.sum())
    return metrics


def evaluate_policy(cfg: EvalCfg) -> dict[str, float]:
    """Evaluate ``cfg.policy_path``; returns ``<material>/v<speed>/{success_rate,vel_error,...}`` and ``all/...``."""
    import onnxruntime as ort

    meta = _read_metadata(cfg.policy_path)
    cells = _cells(cfg)
    env = _build_env(cfg, meta, len(cells))
    recorders: list[Any] = []
    try:
        commands = _pin_cells(env, cells)
        session = ort.InferenceSession(cfg.policy_path, providers=["CPUExecutionProvider"])
        if cfg.record_dir is not None:
            recorders = _make_recorders(cfg, env, meta, cells)
        raw = _rollout(env, session, commands, round(cfg.duration_s / env.step_dt), recorders)
        for rec in recorders:
            rec.close("completed")
    finally:
        for rec in recorders:
            if not rec.closed:
                rec.close("exception during evaluation")
        env.close()
    metrics = _summarize(cells, raw)
    if cfg.out_path is not None:
        Path(cfg.out_path).parent.mkdir(parents=True, exist_ok=True)
        Path(cfg.out_path).write_text(json.dumps(metrics, indent=1))
    return metrics
