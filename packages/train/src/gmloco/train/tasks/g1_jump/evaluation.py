# SPDX-License-Identifier: Apache-2.0
"""Jump attempts in the training simulator: roll a policy out, score it, draw base height and foot depth.

:func:`rollout_jump` plays one unassisted jump per env from the reference's first frame (no RSI, no assist, no
noise, no robot DR) on one material preset, and records a :class:`~gmloco.train.tasks.g1_jump.metrics.JumpTrace`
per env; :func:`evaluate_jump` builds the env, runs ``attempts`` envs at once and scores them with
:func:`~gmloco.train.tasks.g1_jump.metrics.jump_metrics`; :func:`fig_jump_trace` plots traces.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch

from gmloco.train.config import ContactModelName
from gmloco.train.tasks.g1_jump.config import JumpMotionName, JumpTaskCfg, g1_jump_task
from gmloco.train.tasks.g1_jump.metrics import JumpMetrics, JumpTrace, jump_metrics

__all__ = ["JumpEvalCfg", "evaluate_jump", "evaluate_jump_run", "fig_jump_trace", "rollout_jump", "summarize"]

Policy = Callable[[dict[str, torch.Tensor]], torch.Tensor]
"""Observation groups of the env (``actor``, ``critic``; each [N, D]) -> action [N, 29]."""


@dataclass
class JumpEvalCfg:
    """One evaluation: contact model, material, motion, attempts."""

    contact_model: ContactModelName = "rft3d"
    """Contact model of the simulator (``"rigid"`` ignores ``material``)."""
    material: str = "dry_sand"
    """``gmloco.contact.MATERIAL_PRESETS`` name: basalt, dry_sand, beach_sand or poppy_seed."""
    motion: JumpMotionName = "vertical"
    """Reference the policy was trained on."""
    attempts: int = 20
    """Jumps, one per env, run in parallel."""
    policy_history_length: int = 5
    """Stacked actor frames the policy was trained with."""
    seed: int = 0
    """Env seed."""
    device: str = "cpu"
    """Torch / Warp device."""


def _task(cfg: JumpEvalCfg) -> JumpTaskCfg:
    """Play-mode jump task on the chosen material."""
    task = g1_jump_task(cfg.contact_model, cfg.motion, play=True)
    base = replace(
        task.base,
        material=replace(task.base.material, preset=cfg.material),
        policy_history_length=cfg.policy_history_length,
    )
    return replace(task, base=base)


def _tilt(quat: torch.Tensor) -> torch.Tensor:
    """Angle between the body z axis and the world z axis [rad] for (w, x, y, z) quaternions [N, 4]."""
    _, x, y, _ = quat.unbind(-1)
    cos = 1.0 - 2.0 * (x * x + y * y)  # R_zz
    return torch.arccos(cos.clamp(-1.0, 1.0))


def rollout_jump(env: Any, policy: Policy, steps: int | None = None) -> list[JumpTrace]:
    """Reset ``env`` (a play-mode jump env), run ``policy`` for ``steps`` (default: one episode), one trace per env.

    Envs that fail stop recording at their failure (the env would reset them); their trace ends there, while the
    reference track covers all ``steps``.
    """
    from gmloco.train.sand import get_sand
    from gmloco.train.tasks.g1_jump.command import get_jump

    obs, _ = env.reset()
    jump, robot, sand = get_jump(env), env.scene["robot"], get_sand(env)
    steps = steps if steps is not None else int(env.max_episode_length) - 1
    origin = jump.origin.clone()
    rec: dict[str, list[torch.Tensor]] = {k: [] for k in ("base", "height", "tilt", "feet", "fh", "contact")}
    # The reference on its own clock (samples after each step), unaffected by resets of failed envs.
    times = (torch.arange(steps, device=env.device) + 1) * env.step_dt
    ref_track = (jump.ref.sample("base_pos", jump.start_time[0] + times)).cpu().numpy()
    alive = torch.ones(env.num_envs, dtype=torch.bool, device=env.device)
    ended = torch.full((env.num_envs,), steps, dtype=torch.long)
    for i in range(steps):
        with torch.inference_mode():
            obs, _, terminated, truncated, _ = env.step(policy(obs))
        feet = sand.feet.update()
        pos = robot.data.root_link_pos_w
        rec["base"].append(pos - origin)
        rec["height"].append(pos[:, 2] - sand.surface_height(pos[:, 0], pos[:, 1]))
        rec["tilt"].append(_tilt(robot.data.root_link_quat_w))
        rec["feet"].append(robot.data.site_pos_w[:, jump.feet_site_ids] - origin.unsqueeze(1))
        rec["fh"].append(feet.height.clone())
        rec["contact"].append(feet.in_contact.clone())
        done = (terminated | truncated).cpu() & alive.cpu()
        ended[done] = i + 1
        alive &= ~(terminated | truncated)
    arrays = {k: torch.stack(v, dim=1).cpu().numpy() for k, v in rec.items()}
    return [
        JumpTrace(
            dt=float(env.step_dt),
            base_pos=arrays["base"][n, : ended[n]],
            base_height=arrays["height"][n, : ended[n]],
            tilt=arrays["tilt"][n, : ended[n]],
            feet_pos=arrays["feet"][n, : ended[n]],
            foot_height=arrays["fh"][n, : ended[n]],
            in_contact=arrays["contact"][n, : ended[n]].astype(bool),
            ref_base_pos=ref_track,
            push_start_s=jump.ref.t_push_start,
            sole_height=_sole_height(),
        )
        for n in range(env.num_envs)
    ]


def _sole_height() -> float:
    """Sole-site height above flat ground of the shipped references [m]."""
    from gmloco.train.tasks.g1_jump.reference import load_reference, reference_path

    return load_reference(reference_path("vertical")).sole_height


def summarize(metrics: list[JumpMetrics]) -> dict[str, float]:
    """Return the per-(policy, medium, simulator) keys of ``results/jump/summary.json``.

    ``success_pct``, ``height_error_pct``, ``takeoff_slip_cm``, ``sinkage_cm`` (means over the attempts) and
    ``episodes``.
    """
    if not metrics:
        raise ValueError("no attempts to summarize")
    mean = lambda key: float(np.nanmean([getattr(m, key) for m in metrics]))  # noqa: E731
    return {
        "success_pct": 100.0 * float(np.mean([m.landing_success for m in metrics])),
        "height_error_pct": mean("height_error_pct"),
        "takeoff_slip_cm": mean("takeoff_slip_cm"),
        "sinkage_cm": mean("sinkage_cm"),
        "episodes": float(len(metrics)),
    }


def _make_env(cfg: JumpEvalCfg) -> Any:
    """The play-mode jump env of ``cfg`` with ``cfg.attempts`` envs."""
    from mjlab.envs import ManagerBasedRlEnv

    from gmloco.train.tasks.g1_jump.env_cfgs import make_g1_jump_env_cfg

    if cfg.attempts < 1:
        raise ValueError(f"attempts must be >= 1, got {cfg.attempts}")
    env_cfg = make_g1_jump_env_cfg(_task(cfg), cfg.attempts)
    env_cfg.seed = cfg.seed
    return ManagerBasedRlEnv(cfg=env_cfg, device=cfg.device)


def evaluate_jump(policy: Policy, cfg: JumpEvalCfg) -> tuple[dict[str, float], list[JumpTrace]]:
    """Run ``cfg.attempts`` unassisted jumps with ``policy`` and return the summary and the traces."""
    env = _make_env(cfg)
    try:
        traces = rollout_jump(env, policy)
    finally:
        env.close()
    return summarize([jump_metrics(t) for t in traces]), traces


def evaluate_jump_run(run_dir: str | Path, cfg: JumpEvalCfg) -> tuple[dict[str, float], list[JumpTrace]]:
    """Evaluate the newest checkpoint of a jump training run (``train_cfg.json`` + ``model_<it>.pt``).

    The motion, stacked actor frames and network widths come from the run's ``train_cfg.json``; ``cfg`` chooses
    the contact model and material of the evaluation, so a PPO-Rigid policy can be scored on sand.

    Raises:
        ValueError: If ``run_dir`` holds no jump run or no checkpoint.
    """
    import json
    from dataclasses import asdict

    from mjlab.rl import RslRlVecEnvWrapper
    from tensordict import TensorDict

    from gmloco.train.rl.runner import GmlocoOnPolicyRunner, latest_checkpoint
    from gmloco.train.tasks.g1_granular import make_g1_granular_ppo_cfg

    run = Path(run_dir)
    cfg_file, checkpoint = run / "train_cfg.json", latest_checkpoint(run)
    saved = json.loads(cfg_file.read_text()) if cfg_file.is_file() else {}
    if not saved.get("jump") or checkpoint is None:
        raise ValueError(f"{run} holds no jump training run with a checkpoint (train_cfg.json with 'jump', model_*.pt)")
    jump = saved["jump"]
    cfg = replace(cfg, motion=jump["motion"], policy_history_length=int(jump["base"]["policy_history_length"]))
    env = RslRlVecEnvWrapper(_make_env(cfg))
    try:
        agent = make_g1_granular_ppo_cfg(hidden_dims=tuple(saved["hidden_dims"]))
        runner = GmlocoOnPolicyRunner(env, asdict(agent), None, cfg.device)
        runner.load(str(checkpoint), map_location=cfg.device)
        act = runner.get_inference_policy(cfg.device)
        n = env.unwrapped.num_envs
        traces = rollout_jump(env.unwrapped, lambda obs: act(TensorDict(obs, batch_size=[n])))
    finally:
        env.close()
    return summarize([jump_metrics(t) for t in traces]), traces


def fig_jump_trace(traces: dict[str, JumpTrace], path: str | Path) -> Path:
    """Plot pelvis height and foot depth over one jump per label (e.g. PPO-3D-RFT and PPO-Rigid); returns the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_h, ax_d) = plt.subplots(2, 1, figsize=(6.0, 5.0), sharex=True)
    for label, tr in traces.items():
        t = np.arange(tr.base_pos.shape[0]) * tr.dt
        line = ax_h.plot(t, tr.base_pos[:, 2], label=label)[0]
        depth = 100.0 * np.clip(tr.sole_height - tr.foot_height.min(axis=-1), 0.0, None)
        ax_d.plot(t, depth, color=line.get_color(), label=label)
    first = next(iter(traces.values()))
    t_ref = np.arange(first.ref_base_pos.shape[0]) * first.dt
    ax_h.plot(t_ref, first.ref_base_pos[:, 2], "k--", lw=1.0, label="reference")
    ax_h.set_ylabel("pelvis height [m]")
    ax_d.set_ylabel("deepest sole depth [cm]")
    ax_d.set_xlabel("time [s]")
    ax_h.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.tmp{out.suffix}")
    fig.savefig(tmp, dpi=150)
    plt.close(fig)
    tmp.replace(out)
    return out
