# SPDX-License-Identifier: Apache-2.0
"""Evaluate the GM-Loco teacher-student pair in the granular training simulator (issue 6).

One :func:`evaluate_teacher_student` call rebuilds the student (with its frozen teacher, both stored in a
``StudentPPO`` checkpoint) on a play-mode env with the ``history`` group, and measures:

* **decoded eta on unseen materials**: every env is one cell, a material (a grid over the held-out (rho_c, mu_int)
  rectangle that the training DR never draws, :class:`~gmloco.train.teacher_student.HeldOutRegionCfg`, or a named
  preset) x a commanded forward speed x a repeat. The student acts; at every step the teacher labels the same state.
  R^2 of psi(z_hat) (student) and psi(mu) (teacher) against the true eta, pooled over alive steps after a warm-up
  (the history needs N steps to fill), per group ``held_out`` / ``presets`` / ``all``;
* **student vs teacher**: mean squared action difference per joint on the student's states (DAgger's error);
* **walking**: success (no fall for ``duration_s``; pelvis < 0.2 m above the sand or |roll|, |pitch| > pi/4 is a
  fall, GM-Loco's rules as in :mod:`gmloco.train.evaluation`) and velocity / yaw-rate tracking error, per cell;
  the PPO baseline (an mjlab ONNX export) is scored on the same cells (held-out materials included) with the env
  builder and rollout of :mod:`gmloco.train.evaluation`, under the same floor, commands, duration and failure rules;
* **adaptation** (:func:`adaptation_rollout`): a course basalt -> dry sand -> poppy seed along each robot's initial
  heading. The training simulator's material is per env, so each env's material is switched when its pelvis crosses
  an edge (the contact package's per-point material field is not wired into the training env); decoded eta and the
  left foot's swing apex (sole height above the free surface at the highest point of each swing) against distance.

With ``TsEvalCfg.actor = "teacher"`` the teacher of a ``TeacherPPO`` checkpoint acts instead and only the adaptation
walk runs (on ``adaptation_envs`` envs): its per-material swing apexes measure a teacher's clearance before a
distillation. Reward weights do not enter a rollout (they only scale the reward terms), so a teacher trained with
``--reward-weight`` overrides is rebuilt with the default task.

Heavy imports (mjlab, the env stack, matplotlib) happen inside the functions.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np
import torch

import gmloco.contact as gc
from gmloco.contact import MATERIAL_PRESETS
from gmloco.train.config import ContactModelName, TerrainName
from gmloco.train.evaluation import RolloutCriteriaCfg, accumulate_tracking, tracking_stats
from gmloco.train.mdp.commands import hold_twist
from gmloco.train.teacher_student.heldout import DEFAULT_HELD_OUT, HeldOutRegionCfg, r2_score

__all__ = [
    "TsEvalCfg",
    "adaptation_rollout",
    "decoded_eta_check",
    "evaluate_teacher_adaptation",
    "evaluate_teacher_student",
    "pinned_walk",
    "swing_apexes",
]


@dataclass
class TsEvalCfg(RolloutCriteriaCfg):
    """Held-out evaluation of a distilled student (and its teacher) in the granular training simulator.

    Commands, cells and failure rules: :class:`~gmloco.train.evaluation.RolloutCriteriaCfg` (as ``EvalCfg``).
    """

    actor: Literal["student", "teacher"] = "student"
    """Acting policy: ``"student"`` (every evaluation) or ``"teacher"`` (``teacher_checkpoint``; the adaptation walk
    alone, as the held-out eta, action-error and baseline parts are about the student)."""
    student_checkpoint: str = "artifacts/gm_loco_student_clr50/checkpoint.pt"
    """``StudentPPO`` checkpoint (holds the frozen teacher in ``teacher_state_dict``)."""
    teacher_checkpoint: str = "artifacts/gm_loco_teacher_clr50/checkpoint.pt"
    """``TeacherPPO`` checkpoint, used when ``actor`` is ``"teacher"``."""
    baseline_policy: str | None = "artifacts/ppo_rft3d/policy.onnx"
    """PPO baseline (mjlab ONNX export) scored on the named presets; None: skip."""
    contact_model: ContactModelName = "rft3d"
    """Contact model of the simulator."""
    foot_faces: Literal["sole", "box"] = "sole"
    """Foot-box faces the RFT models sample (``GranularTaskCfg.foot_faces``); the PPO baseline always runs on the
    sole."""
    terrain: TerrainName = "flat"
    """Sand terrain."""
    latent_dim: int = 16
    """Latent size the checkpoint was trained with."""
    history_length: int = 50
    """N of the history group the checkpoint was trained with."""
    tcn_channels: tuple[int, int, int] = (32, 32, 32)
    """Student convolution channels the checkpoint was trained with."""
    held_out: HeldOutRegionCfg = field(default_factory=lambda: DEFAULT_HELD_OUT)
    """The (rho_c, mu_int) rectangle never drawn in training."""
    held_out_grid: tuple[int, int] = (3, 3)
    """Grid points of held-out materials along rho_c and mu_int."""
    held_out_mu_surf: float = 0.45
    """Surface friction of the held-out materials [-] (mu_surf is not part of the region)."""
    presets: tuple[str, ...] = ("basalt", "dry_sand", "beach_sand", "poppy_seed")
    """Named presets (``gmloco.contact.MATERIAL_PRESETS``)."""
    eta_warmup_s: float = 1.0
    """Steps before this time are left out of the eta metrics (history filling) [s]."""
    adaptation_materials: tuple[str, ...] = ("basalt", "dry_sand", "poppy_seed")
    """Materials of the adaptation course, in walking order."""
    adaptation_edges: tuple[float, ...] = (3.0, 6.0)
    """Distances along the initial heading where the material changes [m]."""
    adaptation_speed: float = 1.0
    """Commanded forward speed on the adaptation course [m/s]."""
    adaptation_duration_s: float = 10.0
    """Duration of the adaptation walk [s]; 0 skips it."""
    adaptation_envs: int = 16
    """Envs of the walk when it runs alone (``actor="teacher"``); the student's walk uses the cells' envs."""
    device: str = "cpu"
    """Torch / Warp device."""
    seed: int = 0
    """Env seed."""
    out_dir: str | None = None
    """If set: ``summary.json``, ``materials.csv`` and ``adaptation.{png,json}`` are written here."""


@dataclass(frozen=True)
class _Cell:
    """One env: material, command, group."""

    label: str
    rho_c: float
    mu_int: float
    mu_surf: float
    speed: float
    group: str


def _cells(cfg: TsEvalCfg) -> list[_Cell]:
    """Held-out grid and presets x speeds x repeats, material-major."""
    materials: list[tuple[str, float, float, float, str]] = []
    for rho, mu in zip(*cfg.held_out.grid(*cfg.held_out_grid), strict=True):
        materials.append((f"held_out_rho{rho:.0f}_mu{mu:.3f}", float(rho), float(mu), cfg.held_out_mu_surf, "held_out"))
    for name in cfg.presets:
        p = gc.MATERIAL_PRESETS[name]
        materials.append((name, float(p.rho_c), float(p.mu_int), float(p.mu_surf), "presets"))
    return [_Cell(*m[:4], s, m[4]) for m in materials for s in cfg.speeds for _ in range(cfg.repeats)]  # type: ignore[misc]


def _student_entries(cfg: TsEvalCfg) -> dict[str, Any]:
    """rsl-rl entries of the student with the network sizes of ``cfg`` (the rest: package defaults)."""
    from gmloco.train.teacher_student import DistillCfg, StudentCfg, TeacherCfg, student_train_entries

    teacher = TeacherCfg(latent_dim=cfg.latent_dim)
    student = StudentCfg(history_length=cfg.history_length, tcn_channels=cfg.tcn_channels)
    return student_train_entries(teacher, student, DistillCfg())


def _actor_entries(cfg: TsEvalCfg) -> tuple[str, dict[str, Any]]:
    """Checkpoint and rsl-rl entries of the acting policy (the teacher's as ``train_ts_chunk.py --stage teacher``)."""
    from gmloco.train.teacher_student import ObsGroupsCfg, TeacherCfg

    if cfg.actor == "teacher":
        return cfg.teacher_checkpoint, TeacherCfg(latent_dim=cfg.latent_dim).to_rsl_rl(ObsGroupsCfg())
    return cfg.student_checkpoint, _student_entries(cfg)


def _build_runner(cfg: TsEvalCfg, num_envs: int, duration_s: float) -> Any:
    """Play-mode env (eval floor, failure terminations, fixed commands) + runner with the acting checkpoint."""
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.managers.termination_manager import TerminationTermCfg
    from mjlab.rl import RslRlVecEnvWrapper

    from gmloco.train import mdp
    from gmloco.train.rl.runner import GmlocoOnPolicyRunner
    from gmloco.train.tasks.g1_granular import g1_granular_task, make_g1_granular_env_cfg, make_g1_granular_ppo_cfg

    task = g1_granular_task(cfg.contact_model, cfg.terrain, play=True)
    task = replace(
        task, terrain=replace(task.terrain, floor=cfg.floor), command_curriculum=False, foot_faces=cfg.foot_faces
    )
    task.policy_history_length, task.episode_length_s = 1, duration_s + 1.0
    env_cfg = make_g1_granular_env_cfg(task, num_envs, cfg.history_length)
    env_cfg.seed = cfg.seed
    env_cfg.terminations = {
        "base_too_low": TerminationTermCfg(func=mdp.base_height_below, params={"min_height": cfg.min_base_height}),
        "tilt": TerminationTermCfg(func=mdp.roll_pitch_exceeds, params={"limit": cfg.max_tilt}),
    }
    twist = env_cfg.commands["twist"]
    twist.resampling_time_range = (1.0e9, 1.0e9)  # type: ignore[attr-defined]
    twist.rel_standing_envs, twist.rel_heading_envs, twist.heading_command = 0.0, 0.0, False  # type: ignore[attr-defined]
    twist.rel_world_envs, twist.rel_forward_envs, twist.ranges.heading = 0.0, 0.0, None  # type: ignore[attr-defined]
    env = RslRlVecEnvWrapper(ManagerBasedRlEnv(cfg=env_cfg, device=cfg.device))
    checkpoint, entries = _actor_entries(cfg)
    runner = GmlocoOnPolicyRunner(env, asdict(make_g1_granular_ppo_cfg()) | entries, None, cfg.device)
    runner.load(checkpoint, map_location=cfg.device)
    if cfg.actor == "student" and not getattr(runner.alg, "teacher_loaded", False):
        raise ValueError(f"{checkpoint} holds no teacher: evaluate a distilled student checkpoint.")
    return runner


def _pin_materials(env: Any, rho_c: list[float], mu_int: list[float], mu_surf: list[float]) -> None:
    """Fix every env's material (and its eta) now and on later resets."""
    sand = env.sand
    if sand.materials is None:
        raise ValueError("the held-out evaluation needs a granular contact model, not rigid contact")
    as_t = lambda v: torch.tensor(v, dtype=torch.float32, device=env.device)  # noqa: E731
    sand.materials.pin(as_t(rho_c), as_t(mu_int), as_t(mu_surf))
    sand.materials.draw(torch.arange(env.num_envs, device=env.device))


def _start(runner: Any, commands: torch.Tensor) -> Any:
    """Reset every env, fix the commands and rebuild the observation histories with them."""
    from tensordict import TensorDict

    env = runner.env.unwrapped
    env.reset()
    hold_twist(env.command_manager.get_term("twist"), commands)
    ids = torch.arange(env.num_envs, device=env.device)
    env.observation_manager.reset(ids)  # history back-filled with the commanded frame, not the reset one
    obs = env.observation_manager.compute(update_history=True, env_ids=ids)
    return TensorDict(obs, batch_size=[env.num_envs])


def _policy_step(runner: Any, obs: Any) -> dict[str, torch.Tensor]:
    """Acting policy's action and decoded etas on one observation.

    ``StudentPPO`` runner: student action, decoded etas of student and teacher, squared action difference.
    ``TeacherPPO`` runner: teacher action and its decoded eta ``psi(mu)`` (keys ``actions``, ``eta_teacher``).
    """
    from gmloco.train.teacher_student import StudentPPO

    is_student = isinstance(runner.alg, StudentPPO)
    if not is_student:
        with torch.no_grad():
            actions = runner.alg.actor(obs)
            return {"actions": actions, "eta_teacher": runner.alg.actor.decode(runner.alg.actor.latent_mu)[:, 0]}
    student, teacher = runner.alg.actor, runner.alg.teacher
    with torch.no_grad():
        actions = student(obs)
        eta_student = student.decode(student.latent)[:, 0]
        teacher_actions = teacher(obs)
        eta_teacher = teacher.decode(teacher.latent_mu)[:, 0]
    return {
        "actions": actions,
        "eta_student": eta_student,
        "eta_teacher": eta_teacher,
        "action_sq": (actions - teacher_actions).pow(2).mean(dim=-1),
    }


def _rollout(runner: Any, commands: torch.Tensor, steps: int) -> dict[str, np.ndarray]:
    """Run the student; return per-step ``[T, W]`` signals and per-env tracking sums and failure flags."""
    from tensordict import TensorDict

    env = runner.env.unwrapped
    runner.alg.eval_mode()
    obs = _start(runner, commands)
    n = env.num_envs
    alive = torch.ones(n, dtype=torch.bool, device=env.device)
    keys = ("eta_true", "eta_student", "eta_teacher", "action_sq", "alive")
    trace: dict[str, list[torch.Tensor]] = {k: [] for k in keys}
    stats = tracking_stats(n, env.device)
    robot = env.scene["robot"]
    for _ in range(steps):
        out = _policy_step(runner, obs)
        for k in ("eta_student", "eta_teacher", "action_sq"):
            trace[k].append(out[k])
        trace["eta_true"].append(env.sand.eta.clone())
        trace["alive"].append(alive.clone())
        obs_dict, _, terminated, _, _ = env.step(out["actions"])
        obs = TensorDict(obs_dict, batch_size=[n])
        alive &= ~terminated
        accumulate_tracking(stats, robot.data, commands, alive)
    result = {k: torch.stack(v).cpu().numpy() for k, v in trace.items()}
    result |= {k: v.cpu().numpy() for k, v in stats.items()}
    result["failed"] = (~alive).cpu().numpy()
    return result


def pinned_walk(cfg: TsEvalCfg, materials: list[str], commands: list[tuple[float, float, float]],
                duration_s: float) -> dict[str, Any]:  # fmt: skip
    """Walk the acting checkpoint, one env per (material, command), under commands held for ``duration_s``.

    The training simulator's side of a comparison with the MPM evaluation: each env's material preset is pinned
    (``gmloco.contact.MATERIAL_PRESETS`` names) and its command (v_x [m/s], v_y [m/s], w_z [rad/s]) held; an env
    stops counting as alive at its first failure termination.

    Returns:
        ``quat_wxyz`` [T, W, 4] and ``xy`` [T, W, 2] [m] of the pelvis, ``wz`` [T, W] its world yaw rate [rad/s],
        ``alive`` [T, W] (before each step), ``eta_true`` [T, W] the pinned material's normalized stiffness and the
        acting policy's decoded ones (``eta_student`` and ``eta_teacher`` for a student, ``eta_teacher`` for a
        teacher) [-], ``dt`` the policy step [s], ``wall_s`` the time it took [s].
    """
    import time

    from tensordict import TensorDict

    if len(materials) != len(commands):
        raise ValueError(f"pinned_walk: {len(materials)} materials but {len(commands)} commands (one each per env)")
    t0 = time.perf_counter()
    runner = _build_runner(cfg, len(commands), duration_s)
    env = runner.env.unwrapped
    mats = [MATERIAL_PRESETS[m] for m in materials]
    _pin_materials(env, [x.rho_c for x in mats], [x.mu_int for x in mats], [x.mu_surf for x in mats])
    runner.alg.eval_mode()
    obs = _start(runner, torch.tensor(commands, dtype=torch.float32, device=env.device))
    robot, n = env.scene["robot"], len(commands)
    alive = torch.ones(n, dtype=torch.bool, device=env.device)
    trace: dict[str, list[torch.Tensor]] = {"quat_wxyz": [], "xy": [], "wz": [], "alive": [], "eta_true": []}
    for _ in range(round(duration_s / env.step_dt)):
        trace["quat_wxyz"].append(robot.data.root_link_quat_w.clone())
        trace["xy"].append(robot.data.root_link_pos_w[:, :2].clone())
        trace["wz"].append(robot.data.root_link_ang_vel_w[:, 2].clone())
        trace["alive"].append(alive.clone())
        trace["eta_true"].append(env.sand.eta.clone())
        step = _policy_step(runner, obs)
        for k in ("eta_student", "eta_teacher"):
            if k in step:
                trace.setdefault(k, []).append(step[k])
        obs_dict, _, terminated, _, _ = env.step(step["actions"])
        obs = TensorDict(obs_dict, batch_size=[n])
        alive &= ~terminated
    out: dict[str, Any] = {k: torch.stack(v).cpu().numpy() for k, v in trace.items()}
    return out | {"dt": float(env.step_dt), "wall_s": time.perf_counter() - t0}


def finite_json(obj: Any) -> Any:
    """Return ``obj`` with non-finite floats replaced by None (JSON has no NaN), recursively."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: finite_json(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [finite_json(v) for v in obj]
    return obj


def decoded_eta_check(runner: Any, steps: int, warmup_steps: int) -> dict[str, float]:
    """Roll out the runner's acting policy on its env (training DR); return R^2 / MAE of the decoded eta.

    For a ``TeacherPPO`` runner the teacher acts and psi(mu) is scored; for a ``StudentPPO`` runner the student acts
    and both psi(z_hat) and the frozen teacher's psi(mu) on the student's states are scored, plus the student-vs-teacher
    action MSE. Steps before ``warmup_steps`` and the first ``warmup_steps`` after a reset are left out.
    """
    env = runner.env
    runner.alg.eval_mode()
    obs = env.get_observations()
    since_reset = torch.zeros(env.num_envs, dtype=torch.long, device=env.device)
    rows: dict[str, list[torch.Tensor]] = {"true": [], "teacher": [], "student": [], "action_sq": [], "valid": []}
    for _ in range(steps):
        out = _policy_step(runner, obs)
        for key in ("teacher", "student"):
            if f"eta_{key}" in out:
                rows[key].append(out[f"eta_{key}"])
        if "action_sq" in out:
            rows["action_sq"].append(out["action_sq"])
        rows["true"].append(env.unwrapped.sand.eta.clone())
        rows["valid"].append(since_reset >= warmup_steps)
        obs, _, dones, _ = env.step(out["actions"])
        since_reset = torch.where(dones.bool(), 0, since_reset + 1)
    raw = {k: torch.stack(v).cpu().numpy() for k, v in rows.items() if v}
    valid = raw["valid"]
    metrics = {"dr_eta_samples": float(valid.sum()), "dr_eta_std": float(raw["true"][valid].std())}
    for who in ("teacher", "student"):
        if who in raw:
            metrics[f"dr_eta_r2_{who}"] = r2_score(raw[who][valid], raw["true"][valid])
            metrics[f"dr_eta_mae_{who}"] = float(np.mean(np.abs(raw[who][valid] - raw["true"][valid])))
    if "action_sq" in raw:
        metrics["dr_student_teacher_action_mse"] = float(np.mean(raw["action_sq"][valid]))
    return metrics


def _eta_metrics(raw: dict[str, np.ndarray], mask_env: np.ndarray, warmup: int, prefix: str) -> dict[str, float]:
    """Pooled R^2 / MAE of decoded vs true eta over alive steps after ``warmup`` of the envs in ``mask_env``."""
    valid = raw["alive"].astype(bool).copy()
    valid[:warmup] = False
    valid &= mask_env[None, :]
    true = raw["eta_true"][valid]
    metrics = {f"{prefix}/eta_samples": float(valid.sum())}
    for who in ("student", "teacher"):
        pred = raw[f"eta_{who}"][valid]
        metrics[f"{prefix}/eta_r2_{who}"] = r2_score(pred, true)
        metrics[f"{prefix}/eta_mae_{who}"] = float(np.mean(np.abs(pred - true))) if true.size else float("nan")
    metrics[f"{prefix}/student_teacher_action_mse"] = float(np.mean(raw["action_sq"][valid])) if true.size else math.nan
    return metrics


def _walk_metrics(raw: dict[str, np.ndarray], mask_env: np.ndarray, prefix: str) -> dict[str, float]:
    """Success rate and mean tracking errors of the envs in ``mask_env``."""
    steps = np.maximum(raw["steps"], 1.0)
    return {
        f"{prefix}/success_rate": float(np.mean(~raw["failed"][mask_env])),
        f"{prefix}/vel_error": float(np.mean(raw["vel_err"][mask_env] / steps[mask_env])),
        f"{prefix}/yaw_rate_error": float(np.mean(raw["yaw_err"][mask_env] / steps[mask_env])),
        f"{prefix}/num_envs": float(mask_env.sum()),
    }


def _material_rows(cells: list[_Cell], raw: dict[str, np.ndarray], warmup: int) -> list[dict[str, Any]]:
    """Per material: true eta, mean decoded etas, success rate."""
    rows = []
    valid = raw["alive"].astype(bool).copy()
    valid[:warmup] = False
    for label in dict.fromkeys(c.label for c in cells):
        envs = np.array([c.label == label for c in cells])
        cell = next(c for c in cells if c.label == label)
        sel = valid & envs[None, :]
        mean = lambda k: float(raw[k][sel].mean()) if sel.any() else float("nan")  # noqa: E731, B023
        rows.append(
            {
                "material": label,
                "group": cell.group,
                "rho_c": cell.rho_c,
                "mu_int": cell.mu_int,
                "eta_true": mean("eta_true"),
                "eta_student": mean("eta_student"),
                "eta_teacher": mean("eta_teacher"),
                "success_rate": float(np.mean(~raw["failed"][envs])),
            }
        )
    return rows


def _baseline(cfg: TsEvalCfg, cells: list[_Cell]) -> dict[str, float]:
    """Score the PPO baseline (mjlab ONNX, stacked actor frames) on the same cells, floor, commands and rules.

    Uses the env builder and rollout of :mod:`gmloco.train.evaluation` (the baseline's observation layout comes from
    its metadata) with this evaluation's per-env materials, so held-out materials are scored too.
    """
    import onnxruntime as ort

    from gmloco.train import evaluation as ev

    assert cfg.baseline_policy is not None
    ev_cfg = ev.EvalCfg(
        policy_path=cfg.baseline_policy,
        contact_model=cfg.contact_model,
        terrain=cfg.terrain,
        duration_s=cfg.duration_s,
        min_base_height=cfg.min_base_height,
        max_tilt=cfg.max_tilt,
        floor=cfg.floor,
        device=cfg.device,
        seed=cfg.seed,
    )
    env = ev._build_env(ev_cfg, ev._read_metadata(cfg.baseline_policy), len(cells))
    try:
        _pin_materials(env, [c.rho_c for c in cells], [c.mu_int for c in cells], [c.mu_surf for c in cells])
        commands = torch.tensor([[c.speed, 0.0, 0.0] for c in cells], dtype=torch.float32, device=env.device)
        session = ort.InferenceSession(cfg.baseline_policy, providers=["CPUExecutionProvider"])
        raw = ev._rollout(env, session, commands, round(cfg.duration_s / env.step_dt))
    finally:
        env.close()
    return _walk_table(cells, raw)


def _walk_table(cells: list[_Cell], raw: dict[str, np.ndarray]) -> dict[str, float]:
    """Walking metrics per group (``held_out``, ``presets``, ``all``) and per ``<material>/v<speed>`` cell."""
    held = np.array([c.group == "held_out" for c in cells])
    metrics: dict[str, float] = {}
    for name, mask in {"held_out": held, "presets": ~held, "all": np.ones(len(cells), dtype=bool)}.items():
        if mask.any():
            metrics |= _walk_metrics(raw, mask, name)
    for key in dict.fromkeys((c.label, c.speed) for c in cells):
        metrics |= _walk_metrics(raw, np.array([(c.label, c.speed) == key for c in cells]), f"{key[0]}/v{key[1]:g}")
    return metrics


def _comparison(cells: list[_Cell], student: dict[str, float], baseline: dict[str, float]) -> list[dict[str, Any]]:
    """Rows ``cell, student/baseline success and tracking errors`` per cell, then per group."""
    keys = [f"{label}/v{speed:g}" for label, speed in dict.fromkeys((c.label, c.speed) for c in cells)]
    rows = []
    for key in [*keys, "held_out", "presets", "all"]:
        row: dict[str, Any] = {"cell": key}
        for name in ("success_rate", "vel_error", "yaw_rate_error"):
            row[f"student_{name}"] = student.get(f"{key}/{name}")
            row[f"baseline_{name}"] = baseline.get(f"{key}/{name}")
        rows.append(row)
    return rows


def swing_apexes(height: np.ndarray, in_contact: np.ndarray, alive: np.ndarray, min_steps: int = 3) -> list[int]:
    """Return the step indices of the highest point of each completed swing of one foot.

    A swing is a run of steps with the foot out of contact that ends in a touchdown while the env is alive;
    runs shorter than ``min_steps`` (contact flicker) are ignored.

    Args:
        height: Sole height above the free surface [m], ``[T]``.
        in_contact: Foot contact flags, ``[T]``.
        alive: Env alive flags, ``[T]``.
        min_steps: Shortest swing counted [steps].
    """
    apexes, start = [], None
    for t in range(len(height)):
        if not alive[t]:
            break
        if not in_contact[t] and start is None:
            start = t
        elif in_contact[t] and start is not None:
            if t - start >= min_steps:
                apexes.append(start + int(np.argmax(height[start:t])))
            start = None
    return apexes


def _course_table(cfg: TsEvalCfg) -> torch.Tensor:
    """(rho_c, mu_int, mu_surf) of the course materials, ``[M, 3]``."""
    presets = [gc.MATERIAL_PRESETS[m] for m in cfg.adaptation_materials]
    return torch.tensor([[p.rho_c, p.mu_int, p.mu_surf] for p in presets], dtype=torch.float32)


def adaptation_rollout(runner: Any, cfg: TsEvalCfg) -> dict[str, Any]:
    """Walk every env along the course with the runner's acting policy (student or teacher).

    The material of env w is the course material at its distance s_w = (p_w - p_w(0)) . h_w(0) along its initial
    heading; it is switched (in place, with its eta) when s_w crosses an edge.

    Returns:
        ``trace``: per-step ``[T, W]`` arrays ``s`` [m], ``material`` (course index), ``eta_true``, the decoded etas
        (``eta_teacher``; ``eta_student`` when the student acts), ``v_forward`` (pelvis velocity along the initial
        heading [m/s]), ``left_height`` [m], ``left_contact``, ``alive``; ``per_material``: rows of
        :func:`_adaptation_stats`; ``survived``: envs alive at the end.
    """
    env = runner.env.unwrapped
    n, dev = env.num_envs, env.device
    table = _course_table(cfg).to(dev)
    edges = torch.tensor(cfg.adaptation_edges, dtype=torch.float32, device=dev)
    index = torch.zeros(n, dtype=torch.long, device=dev)
    _pin_materials(env, *(table[index].T.tolist()))
    commands = torch.tensor([[cfg.adaptation_speed, 0.0, 0.0]] * n, device=dev)
    runner.alg.eval_mode()
    obs = _start(runner, commands)
    robot, feet = env.scene["robot"], env.sand.feet
    p0 = robot.data.root_link_pos_w[:, :2].clone()
    q = robot.data.root_link_quat_w
    yaw = torch.atan2(2 * (q[:, 0] * q[:, 3] + q[:, 1] * q[:, 2]), 1 - 2 * (q[:, 2] ** 2 + q[:, 3] ** 2))
    heading = torch.stack([torch.cos(yaw), torch.sin(yaw)], dim=-1)
    alive = torch.ones(n, dtype=torch.bool, device=dev)
    trace: dict[str, list[torch.Tensor]] = {}
    from tensordict import TensorDict

    for _ in range(round(cfg.adaptation_duration_s / env.step_dt)):
        s = ((robot.data.root_link_pos_w[:, :2] - p0) * heading).sum(-1)
        new_index = torch.searchsorted(edges, s.contiguous(), right=True)
        if bool((new_index != index).any()):
            index = new_index
            _pin_materials(env, *(table[index].T.tolist()))
        out = _policy_step(runner, obs)
        feet.update()
        step = {"s": s, "material": index.float(), "eta_true": env.sand.eta}
        step |= {k: out[k] for k in ("eta_student", "eta_teacher") if k in out}
        step["v_forward"] = (robot.data.root_link_lin_vel_w[:, :2] * heading).sum(-1)
        step |= {
            "left_height": feet.height[:, 0],
            "left_contact": feet.in_contact[:, 0].float(),
            "alive": alive.float(),
        }
        for k, v in step.items():
            trace.setdefault(k, []).append(v.clone())
        obs_dict, _, terminated, _, _ = env.step(out["actions"])
        obs = TensorDict(obs_dict, batch_size=[n])
        alive &= ~terminated
    raw = {k: torch.stack(v).cpu().numpy() for k, v in trace.items()}
    return {"trace": raw, "per_material": _adaptation_stats(cfg, raw), "survived": int(alive.sum())}


def _adaptation_stats(cfg: TsEvalCfg, raw: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    """Per course material: left-foot swings, apex and lift statistics, falls, forward speed, mean etas.

    An apex counts for the material under the pelvis at the apex step. ``swing_apex_*``: sole height above the free
    surface at the apex [m]; ``swing_lift_mean_m``: apex minus the lowest sole height since the previous apex (the
    first swing: since the start), i.e. how far the foot rises from its sunken stance [m] (contact is a 40 N force
    threshold, so on soft ground a foot can leave "contact" while still sunk); ``falls``: envs that failed there;
    ``eta_student`` only when it was traced (student acting).
    """
    materials = range(len(cfg.adaptation_materials))
    apex_by_material: dict[int, list[float]] = {i: [] for i in materials}
    lift_by_material: dict[int, list[float]] = {i: [] for i in materials}
    falls = dict.fromkeys(materials, 0)
    for w in range(raw["s"].shape[1]):
        height = raw["left_height"][:, w]
        contact, alive = raw["left_contact"][:, w] > 0.5, raw["alive"][:, w] > 0.5
        previous = 0
        for t in swing_apexes(height, contact, alive):
            apex_by_material[int(raw["material"][t, w])].append(float(height[t]))
            lift_by_material[int(raw["material"][t, w])].append(float(height[t] - height[previous : t + 1].min()))
            previous = t
        if not alive[-1]:
            falls[int(raw["material"][max(int(alive.sum()) - 1, 0), w])] += 1
    rows = []
    for i, name in enumerate(cfg.adaptation_materials):
        sel = (raw["material"] == i) & (raw["alive"] > 0.5)
        apex, lift = np.asarray(apex_by_material[i]), np.asarray(lift_by_material[i])
        row: dict[str, Any] = {
            "material": name,
            "steps": int(sel.sum()),
            "falls": falls[i],
            "swings": int(apex.size),
            "swing_apex_mean_m": float(apex.mean()) if apex.size else None,
            "swing_apex_std_m": float(apex.std()) if apex.size else None,
            "swing_apex_p90_m": float(np.percentile(apex, 90)) if apex.size else None,
            "swing_lift_mean_m": float(lift.mean()) if lift.size else None,
        }
        for key in ("v_forward", "eta_true", "eta_student", "eta_teacher"):
            if key in raw:
                row[key] = float(raw[key][sel].mean()) if sel.any() else None
        rows.append(row)
    return rows


def fig_adaptation(cfg: TsEvalCfg, result: dict[str, Any], path: Path, env_index: int = 0) -> None:
    """Decoded vs true eta and left-foot sole height (swing apexes marked) against distance, one env."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    raw, w = result["trace"], env_index
    alive = raw["alive"][:, w] > 0.5
    s = raw["s"][alive, w]
    fig, ax = plt.subplots(2, 1, figsize=(8, 5), sharex=True, constrained_layout=True)
    ax[0].plot(s, raw["eta_true"][alive, w], "k-", lw=1.5, label="true eta")
    if "eta_student" in raw:
        ax[0].plot(s, raw["eta_student"][alive, w], "C0-", lw=1, label="student psi(z_hat)")
    ax[0].plot(s, raw["eta_teacher"][alive, w], "C1--", lw=1, label="teacher psi(z)")
    course = " -> ".join(m.replace("_", " ") for m in cfg.adaptation_materials)
    ax[0].set(ylabel="normalized stiffness eta [-]", title=f"{course}, {cfg.actor} acting (granular sim)")
    ax[0].legend(fontsize=8)
    ax[1].plot(s, raw["left_height"][alive, w], "C2-", lw=0.8, label="left sole height above sand")
    apex = swing_apexes(raw["left_height"][:, w], raw["left_contact"][:, w] > 0.5, alive)
    ax[1].plot(raw["s"][apex, w], raw["left_height"][apex, w], "C3v", ms=5, label="swing apex")
    ax[1].set(xlabel="distance along the initial heading [m]", ylabel="height [m]")
    ax[1].legend(fontsize=8)
    bounds = [-math.inf, *cfg.adaptation_edges, math.inf]
    s_lo, s_hi = (float(s.min()), float(s.max())) if s.size else (0.0, 1.0)
    for a in ax:
        for i, name in enumerate(cfg.adaptation_materials):
            lo, hi = max(bounds[i], s_lo), min(bounds[i + 1], s_hi)
            if hi > lo:
                a.axvspan(lo, hi, color=f"C{i + 4}", alpha=0.12, lw=0)
                if a is ax[1]:
                    a.text(0.5 * (lo + hi), a.get_ylim()[1], name, ha="center", va="top", fontsize=8)
        a.grid(alpha=0.3)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def evaluate_teacher_student(cfg: TsEvalCfg) -> dict[str, Any]:
    """Run the held-out eta, student-vs-teacher, walking and adaptation evaluations; return the summary dict.

    With ``cfg.actor == "teacher"``: :func:`evaluate_teacher_adaptation` (the adaptation walk alone).
    """
    if cfg.actor == "teacher":
        return evaluate_teacher_adaptation(cfg)
    cells = _cells(cfg)
    runner = _build_runner(cfg, len(cells), max(cfg.duration_s, cfg.adaptation_duration_s))
    env = runner.env.unwrapped
    try:
        _pin_materials(env, [c.rho_c for c in cells], [c.mu_int for c in cells], [c.mu_surf for c in cells])
        commands = torch.tensor([[c.speed, 0.0, 0.0] for c in cells], dtype=torch.float32, device=env.device)
        raw = _rollout(runner, commands, round(cfg.duration_s / env.step_dt))
        warmup = round(cfg.eta_warmup_s / env.step_dt)
        if not all(
            bool(cfg.held_out.contains(np.asarray(c.rho_c), np.asarray(c.mu_int))) == (c.group == "held_out")
            for c in cells
        ):
            raise AssertionError("a preset lies inside the held-out region, or a held-out cell outside it")
        metrics: dict[str, float] = {}
        groups = {"held_out": np.array([c.group == "held_out" for c in cells]), "all": np.ones(len(cells), bool)}
        groups["presets"] = ~groups["held_out"]
        for name, mask in groups.items():
            metrics |= _eta_metrics(raw, mask, warmup, name)
        metrics |= _walk_table(cells, raw)
        adaptation = adaptation_rollout(runner, cfg) if cfg.adaptation_duration_s > 0 else None
    finally:
        runner.env.close()
    summary: dict[str, Any] = {
        "metrics": metrics,
        "materials": _material_rows(cells, raw, warmup),
        "held_out_region": asdict(cfg.held_out),
        "adaptation": None if adaptation is None else adaptation["per_material"],
        "adaptation_survived": None if adaptation is None else adaptation["survived"],
        "cfg": json.loads(json.dumps(asdict(cfg), default=str)),
    }
    if cfg.baseline_policy is not None:
        baseline = _baseline(cfg, cells)
        summary["baseline"] = baseline
        summary["comparison"] = _comparison(cells, metrics, baseline)
    if cfg.out_dir is not None:
        _write(cfg, summary, adaptation)
    return summary


def evaluate_teacher_adaptation(cfg: TsEvalCfg) -> dict[str, Any]:
    """Walk the adaptation course with the teacher of ``cfg.teacher_checkpoint`` acting on ``cfg.adaptation_envs``.

    Returns the summary dict: ``adaptation`` (per-material rows of :func:`_adaptation_stats`: ``steps``,
    ``falls``, ``swings``, ``swing_apex_mean_m``, ``swing_apex_std_m``, ``swing_apex_p90_m``, ``swing_lift_mean_m``,
    ``v_forward``, ``eta_true``, ``eta_teacher``), ``adaptation_survived`` and ``cfg``; written with the figure
    and env 0's trace to ``cfg.out_dir`` if set.
    """
    if cfg.actor != "teacher" or cfg.adaptation_duration_s <= 0:
        raise ValueError("evaluate_teacher_adaptation needs actor='teacher' and adaptation_duration_s > 0")
    runner = _build_runner(cfg, cfg.adaptation_envs, cfg.adaptation_duration_s)
    try:
        adaptation = adaptation_rollout(runner, cfg)
    finally:
        runner.env.close()
    summary = {
        "actor": cfg.actor,
        "checkpoint": cfg.teacher_checkpoint,
        "adaptation": adaptation["per_material"],
        "adaptation_survived": adaptation["survived"],
        "cfg": json.loads(json.dumps(asdict(cfg), default=str)),
    }
    if cfg.out_dir is not None:
        _write(cfg, summary, adaptation)
    return summary


def _write(cfg: TsEvalCfg, summary: dict[str, Any], adaptation: dict[str, Any] | None) -> None:
    """Write ``summary.json``, ``materials.csv`` (if the summary has materials) and the adaptation figure + trace."""
    import csv

    out = Path(cfg.out_dir)  # type: ignore[arg-type]
    out.mkdir(parents=True, exist_ok=True)
    (out / "summary.json").write_text(json.dumps(finite_json(summary), indent=1, default=str))
    if summary.get("materials"):
        with (out / "materials.csv").open("w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(summary["materials"][0]))
            writer.writeheader()
            writer.writerows(summary["materials"])
    if adaptation is not None:
        fig_adaptation(cfg, adaptation, out / "adaptation.png")
        trace = {k: v[:, 0].tolist() for k, v in adaptation["trace"].items()}
        (out / "adaptation_env0.json").write_text(json.dumps(trace))
