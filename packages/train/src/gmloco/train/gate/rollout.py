# SPDX-License-Identifier: Apache-2.0
"""Roll the gate's cells out in the granular training simulator, a batch of ``num_envs`` episodes at a time.

Each env is one episode of one :class:`GateCell`: a material pinned for the whole episode and a twist held for
``duration_s`` (commands never resample; a yaw-target policy keeps its heading correction, ``hold_twist``). The
per-step traces of a batch are reduced to per-episode rows right away (:func:`episode_rows`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from typing import Any, Literal

import numpy as np
import torch
from tqdm import tqdm

import gmloco.contact as gc
from gmloco.train.gate.config import GateCfg
from gmloco.train.gate.metrics import (
    circle_reference,
    course_finished_s,
    dtw_path_error,
    heading_drift_deg,
    swing_apex_heights,
)
from gmloco.train.gate.policy import GatePolicy
from gmloco.train.mdp.commands import hold_twist

__all__ = ["GateCell", "episode_rows", "gate_cells", "run_cells"]

CellKind = Literal["forward", "yaw", "circle", "held_out"]
"""What a cell measures: straight walking, turning, the circle, decoded eta on a held-out material."""
Actor = Callable[[dict[str, torch.Tensor]], tuple[torch.Tensor, torch.Tensor | None]]
"""Observation groups -> (actions [W, A], decoded eta [W] or None)."""


@dataclass(frozen=True)
class GateCell:
    """One episode's material and command."""

    kind: CellKind
    """What the cell measures."""
    material: str
    """Preset name, or ``held_out_rho<rho_c>_mu<mu_int>``."""
    rho_c: float
    """Critical density [kg/m^3]."""
    mu_int: float
    """Internal friction [-]."""
    mu_surf: float
    """Surface friction [-]."""
    command: tuple[float, float, float]
    """Held twist (v_x [m/s], v_y [m/s], w_z [rad/s])."""


def gate_cells(cfg: GateCfg) -> list[GateCell]:
    """Every episode of the gate's ``parts``: per material forward, yaw and circle cells, then the held-out grid.

    The forward cells are the ``speeds`` (part ``success``) and ``apex_speed`` (part ``apex``), each once.
    """
    parts = set(cfg.parts)
    speeds = list(cfg.speeds) if "success" in parts else []
    if "apex" in parts and cfg.apex_speed not in speeds:
        speeds.append(cfg.apex_speed)
    commands: list[tuple[CellKind, tuple[float, float, float]]] = []
    for v in speeds:
        commands.append(("forward", (v, 0.0, 0.0)))
    for w in cfg.yaw_rates if "yaw" in parts else ():
        commands.append(("yaw", (cfg.yaw_forward_speed, 0.0, w)))
    if "circle" in parts:
        commands.append(("circle", (cfg.circle_speed, 0.0, cfg.circle_speed / cfg.circle_radius_m)))
    cells = []
    for name in cfg.materials:
        p = gc.MATERIAL_PRESETS[name]
        for kind, cmd in commands:
            cells += [GateCell(kind, name, float(p.rho_c), float(p.mu_int), float(p.mu_surf), cmd)] * cfg.repeats
    if "eta" not in parts:
        return cells
    for rho, mu in zip(*cfg.held_out.grid(*cfg.held_out_grid), strict=True):
        label = f"held_out_rho{rho:.0f}_mu{mu:.3f}"
        cell = GateCell("held_out", label, float(rho), float(mu), cfg.held_out_mu_surf, (cfg.held_out_speed, 0.0, 0.0))
        cells += [cell] * cfg.repeats
    return cells


def _env_cfg(cfg: GateCfg, policy: GatePolicy, history_length: int) -> Any:
    """Play-mode env of the policy's training task: eval floor, failure terminations, held commands."""
    from mjlab.managers.termination_manager import TerminationTermCfg

    from gmloco.train import mdp
    from gmloco.train.tasks.g1_granular import make_g1_granular_env_cfg

    task = replace(
        policy.task,
        play=True,
        contact_model=cfg.contact_model,
        rft_extensions_file=cfg.rft_extensions_file,
        rft_extension_ranges={},  # the fitted terms as fitted: the gate draws no domain randomization of them
        terrain=replace(policy.task.terrain, floor=cfg.floor),
        command_curriculum=False,
        episode_length_s=cfg.duration_s + 1.0,
    )
    env_cfg = make_g1_granular_env_cfg(task, cfg.num_envs, history_length)
    env_cfg.seed = cfg.seed
    env_cfg.terminations = {
        "base_too_low": TerminationTermCfg(func=mdp.base_height_below, params={"min_height": cfg.min_base_height}),
        "tilt": TerminationTermCfg(func=mdp.roll_pitch_exceeds, params={"limit": cfg.max_tilt}),
    }
    twist = env_cfg.commands["twist"]
    twist.resampling_time_range = (1.0e9, 1.0e9)  # type: ignore[attr-defined]
    twist.rel_standing_envs, twist.rel_heading_envs, twist.heading_command = 0.0, 0.0, False  # type: ignore[attr-defined]
    twist.rel_world_envs, twist.rel_forward_envs, twist.ranges.heading = 0.0, 0.0, None  # type: ignore[attr-defined]
    # The yaw-target correction clips w_z + k e_psi to the range: widen it to the gate's commands.
    w_max = max([1.0, *(abs(w) for w in cfg.yaw_rates)])
    twist.ranges.ang_vel_z = (-w_max, w_max)  # type: ignore[attr-defined]
    twist.ranges.lin_vel_x = (-1.0, max([2.5, *cfg.speeds]))  # type: ignore[attr-defined]
    return env_cfg


def _checkpoint_actor(cfg: GateCfg, policy: GatePolicy) -> tuple[Any, Actor]:
    """Env + the student or teacher of ``policy.path`` acting (decoded eta: psi(z_hat) or the teacher's psi(mu))."""
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.rl import RslRlVecEnvWrapper
    from tensordict import TensorDict

    from gmloco.train.evaluation_ts import _policy_step
    from gmloco.train.rl.runner import GmlocoOnPolicyRunner
    from gmloco.train.tasks.g1_granular import make_g1_granular_ppo_cfg

    tc = policy.train_cfg
    env_cfg = _env_cfg(cfg, policy, int(tc["history_length"]))
    env = RslRlVecEnvWrapper(ManagerBasedRlEnv(cfg=env_cfg, device=cfg.device))
    entries = asdict(make_g1_granular_ppo_cfg(hidden_dims=tuple(tc["hidden_dims"]))) | tc["rsl_rl_overrides"]
    runner = GmlocoOnPolicyRunner(env, entries, None, cfg.device)
    runner.load(str(policy.path), map_location=cfg.device)
    runner.alg.eval_mode()
    eta_key = "eta_student" if policy.kind == "student" else "eta_teacher"

    def act(obs: dict[str, torch.Tensor]) -> tuple[torch.Tensor, torch.Tensor | None]:
        step = _policy_step(runner, TensorDict(obs, batch_size=[env.num_envs]))
        return step["actions"], step[eta_key]

    return env.unwrapped, act


def _onnx_actor(cfg: GateCfg, policy: GatePolicy) -> tuple[Any, Actor]:
    """Env + an mjlab ONNX export (batch-1 graph: one call per env) acting; no decoded eta."""
    import onnxruntime as ort
    from mjlab.envs import ManagerBasedRlEnv

    from gmloco.train.evaluation import _read_metadata

    meta = _read_metadata(str(policy.path))
    task = replace(
        policy.task,
        policy_history_length=int(meta.get("observation_history_length", policy.task.policy_history_length)),
        action_scale=float(meta.get("action_scale", policy.task.action_scale)),
    )
    env = ManagerBasedRlEnv(cfg=_env_cfg(cfg, replace(policy, task=task), 0), device=cfg.device)
    session = ort.InferenceSession(str(policy.path), providers=["CPUExecutionProvider"])
    name = session.get_inputs()[0].name

    def act(obs: dict[str, torch.Tensor]) -> tuple[torch.Tensor, torch.Tensor | None]:
        x = obs["actor"].cpu().numpy().astype(np.float32)
        out = np.concatenate([np.asarray(session.run(None, {name: x[i : i + 1]})[0]) for i in range(len(x))])
        return torch.as_tensor(out, device=env.device), None

    return env, act


def _start(env: Any, commands: torch.Tensor) -> dict[str, torch.Tensor]:
    """Reset every env, hold the commands and rebuild the observation histories with them."""
    env.reset()
    hold_twist(env.command_manager.get_term("twist"), commands)
    ids = torch.arange(env.num_envs, device=env.device)
    env.observation_manager.reset(ids)
    return env.observation_manager.compute(update_history=True, env_ids=ids)


def _rollout(
    env: Any, act: Actor, commands: torch.Tensor, steps: int, on_step: Callable[[], object] | None = None
) -> dict[str, np.ndarray]:
    """Run one batch and return its traces (``on_step``, the progress bar, is called once per policy step).

    Returns:
        ``[T, W]`` traces after each step (``x``, ``y`` [m], ``yaw`` [rad], ``wz`` world yaw rate [rad/s],
        ``vx``/``vy`` yaw-frame velocity [m/s], ``alive``, ``eta_true``, ``eta_decoded``, ``ended_<term>`` 1 where
        a failure term fired), ``[T, W, 2]`` feet ``height`` [m] and ``contact``, and the start pose
        ``x0``/``y0``/``yaw0`` ``[W]``.
    """
    from mjlab.utils.lab_api.math import quat_apply_inverse, yaw_quat

    obs = _start(env, commands)
    robot, feet = env.scene["robot"], env.sand.feet
    data = robot.data
    alive = torch.ones(env.num_envs, dtype=torch.bool, device=env.device)
    start = {"x0": data.root_link_pos_w[:, 0], "y0": data.root_link_pos_w[:, 1], "yaw0": data.heading_w}
    out: dict[str, np.ndarray] = {k: v.cpu().numpy().copy() for k, v in start.items()}
    trace: dict[str, list[torch.Tensor]] = {}
    terms = env.termination_manager
    for _ in range(steps):
        if on_step is not None:
            on_step()
        actions, eta = act(obs)
        obs, _, terminated, _, _ = env.step(actions)
        ended = {f"ended_{name}": terms.get_term(name) & alive for name in terms.active_terms}
        alive &= ~terminated
        feet.update()
        v_yaw = quat_apply_inverse(yaw_quat(data.root_link_quat_w), data.root_link_lin_vel_w)
        step = {
            "x": data.root_link_pos_w[:, 0],
            "y": data.root_link_pos_w[:, 1],
            "yaw": data.heading_w,
            "wz": data.root_link_ang_vel_w[:, 2],
            "vx": v_yaw[:, 0],
            "vy": v_yaw[:, 1],
            "alive": alive.float(),
            "eta_true": env.sand.eta,
            "height": feet.height,
            "contact": feet.in_contact.float(),
            **{k: v.float() for k, v in ended.items()},
        }
        if eta is not None:
            step["eta_decoded"] = eta
        for k, v in step.items():
            trace.setdefault(k, []).append(v.detach().clone())
    return out | {k: torch.stack(v).cpu().numpy() for k, v in trace.items()}


def _failure(raw: dict[str, np.ndarray], w: int, dt: float) -> tuple[str | None, float]:
    """The failure term that ended episode ``w`` first and when [s]; (None, nan) when it survived."""
    ended = {k.removeprefix("ended_"): np.flatnonzero(v[:, w] > 0.5) for k, v in raw.items() if k.startswith("ended_")}
    first = {name: int(steps[0]) for name, steps in ended.items() if steps.size}
    if not first:
        return None, float("nan")
    name = min(first, key=first.__getitem__)
    return name, (first[name] + 1) * dt


def episode_rows(cfg: GateCfg, cells: list[GateCell], raw: dict[str, np.ndarray], dt: float) -> list[dict[str, Any]]:
    """Reduce a batch's traces to one row per episode (env), for the cells of the batch.

    Each row: ``failed``; ``vel_error`` (mean |v_xy - v_cmd| [m/s] over alive steps after ``settle_s``);
    ``yaw_rate`` (mean world w_z [rad/s], same steps); ``drift_deg`` (heading change over the episode, survivors
    only); ``dtw_m`` (circle cells: DTW error of the pelvis path against the commanded circle over the alive
    steps); ``apex_m`` (swing apexes of both feet); ``eta`` (decoded and true eta after ``eta_warmup_s``);
    ``failure`` (the failure term that ended the episode, None for a survivor) and ``fail_s`` (when [s]);
    ``stance_sink_m`` (mean depth of a foot in contact below the surface over the alive steps [m]) and
    ``stance_sink_peak_m`` (its 95th percentile: how deep the feet dig at touchdown and push-off [m]);
    ``course_s`` (forward cells: when the pelvis passed ``1 - course_slack`` of the commanded straight line, MPM's
    rule [s]; None when it never did, which fails the episode by MPM's rule even if it did not fall).
    """
    settle, warm = round(cfg.settle_s / dt), round(cfg.eta_warmup_s / dt)
    stride = max(1, round(1.0 / (cfg.dtw_hz * dt)))
    rows = []
    for w, cell in enumerate(cells):
        alive = raw["alive"][:, w] > 0.5
        tracked = alive.copy()
        tracked[:settle] = False
        cmd = np.asarray(cell.command)
        verr = np.hypot(raw["vx"][:, w] - cmd[0], raw["vy"][:, w] - cmd[1])
        failure, fail_s = _failure(raw, w, dt)
        in_contact = (raw["contact"][:, w] > 0.5) & alive[:, None]
        sink = np.maximum(-raw["height"][:, w], 0.0)[in_contact]
        row: dict[str, Any] = {
            "cell": cell,
            "failed": not bool(alive[-1]),
            "failure": failure,
            "fail_s": fail_s,
            "stance_sink_m": float(sink.mean()) if sink.size else float("nan"),
            "stance_sink_peak_m": float(np.percentile(sink, 95.0)) if sink.size else float("nan"),
            "vel_error": float(verr[tracked].mean()) if tracked.any() else float("nan"),
            "yaw_rate": float(raw["wz"][tracked, w].mean()) if tracked.any() else float("nan"),
            "drift_deg": heading_drift_deg(raw["yaw0"][w], raw["yaw"][-1, w]) if alive[-1] else float("nan"),
        }
        if cell.kind == "forward":
            steps = len(alive)
            ref = circle_reference(np.array([raw["x0"][w], raw["y0"][w]]), float(raw["yaw0"][w]), cmd[0], 0.0,
                                   dt * np.arange(steps + 1))  # fmt: skip
            path = np.stack([raw["x"][:, w], raw["y"][:, w]], axis=-1)
            row["course_s"] = course_finished_s(path, ref, dt, cfg.course_slack)
        if cell.kind == "circle":
            n = int(alive.sum())
            times = dt * np.arange(1, n + 1)
            ref = circle_reference(np.array([raw["x0"][w], raw["y0"][w]]), float(raw["yaw0"][w]), cmd[0], cmd[2], times)
            path = np.stack([raw["x"][:n, w], raw["y"][:n, w]], axis=-1)
            row["dtw_m"] = dtw_path_error(path[::stride], ref[::stride])
        row["apex_m"] = [
            h
            for f in range(raw["height"].shape[-1])
            for h in swing_apex_heights(raw["height"][:, w, f], raw["contact"][:, w, f] > 0.5, alive)
        ]
        if "eta_decoded" in raw:
            valid = alive.copy()
            valid[:warm] = False
            row["eta"] = (raw["eta_decoded"][valid, w], raw["eta_true"][valid, w])
        rows.append(row)
    return rows


def run_cells(cfg: GateCfg, policy: GatePolicy, cells: list[GateCell]) -> list[dict[str, Any]]:
    """Run every cell (batches of ``cfg.num_envs``, the last one padded) and return its episode row."""
    from gmloco.train.evaluation_ts import _pin_materials

    env, act = _onnx_actor(cfg, policy) if policy.kind == "ppo" else _checkpoint_actor(cfg, policy)
    rows: list[dict[str, Any]] = []
    n = env.num_envs
    steps = round(cfg.duration_s / env.step_dt)
    batches = -(-len(cells) // n)
    bar = tqdm(total=batches * steps, desc=f"gate: {len(cells)} episodes in {batches} batches", unit="step",
               mininterval=5.0)  # fmt: skip
    try:
        for lo in range(0, len(cells), n):
            batch = cells[lo : lo + n]
            padded = batch + [batch[-1]] * (n - len(batch))
            _pin_materials(env, [c.rho_c for c in padded], [c.mu_int for c in padded], [c.mu_surf for c in padded])
            commands = torch.tensor([c.command for c in padded], dtype=torch.float32, device=env.device)
            with torch.no_grad():
                raw = _rollout(env, act, commands, steps, on_step=bar.update)
            rows += episode_rows(cfg, batch, {k: v[..., : len(batch)] if v.ndim == 1 else v[:, : len(batch)]
                                              for k, v in raw.items()}, float(env.step_dt))  # fmt: skip
    finally:
        bar.close()
        env.close()
    return rows
