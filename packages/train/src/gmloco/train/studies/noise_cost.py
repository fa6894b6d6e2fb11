# SPDX-License-Identifier: Apache-2.0
"""What the task's rewards charge for Gaussian noise on a policy's actions, per reward term.

PPO keeps the action std up when the entropy bonus outweighs what the rewards lose to the noise the std adds. This
study rolls a trained policy out in the training simulator with its mean action plus ``N(0, sigma^2)`` noise in the
policy's action space (what PPO samples in training), for several ``sigma``, and reports per ``sigma`` the reward
rate of each term over the alive steps, the survival and the return over the horizon.

    python -m gmloco.train.studies.noise_cost --policy artifacts/gm_loco_teacher_calibrated \
        --contact-model rft3d_calibrated --floor-depth 0.025 --out noise_cost.json

Bad input exits 2.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.train.config import ContactModelName

__all__ = ["NoiseCostCfg", "noise_rates", "plot_noise_cost", "run_noise_cost"]


@dataclass(frozen=True)
class NoiseCostCfg:
    """The policy, the ground and command it walks, and the noise levels tried."""

    policy_dir: str = "artifacts/gm_loco_teacher_calibrated"
    """Run folder of a teacher or student checkpoint (as the training gate reads it)."""
    noise_stds: tuple[float, ...] = (0.0, 0.5, 0.86, 1.22)
    """Std of the Gaussian noise added to each action dimension [policy action units]."""
    material: str = "dry_sand"
    """Material preset of every env."""
    speed: float = 1.0
    """Held forward command [m/s]."""
    floor_depth: float | None = 0.025
    """Hard floor under the feet this far below the surface [m] (None: the 30 cm deep bed)."""
    contact_model: ContactModelName = "rft3d_calibrated"
    """Granular contact model of the simulator."""
    num_envs: int = field(default=32, metadata={"ge": 1})
    """Envs per noise level."""
    seconds: float = field(default=5.0, metadata={"gt": 0})
    """Horizon of each rollout [s]."""
    device: str = "cpu"
    """Torch / Warp device."""
    seed: int = 0
    """Seed of the env and of the noise."""


def noise_rates(step_rewards: np.ndarray, alive: np.ndarray, names: Sequence[str], dt: float) -> dict[str, Any]:
    """Reduce one rollout's traces to the study's numbers.

    Args:
        step_rewards: ``[T, W, K]`` weighted reward of each term at each step, per second (mjlab's ``_step_reward``).
        alive: ``[T, W]`` whether the env was alive when the step began.
        names: The ``K`` term names.
        dt: Policy step [s].

    Returns:
        ``rate`` (term -> mean weighted reward per second over alive steps [1/s]), ``total_rate`` [1/s],
        ``survival`` (share of envs alive after the last step), ``return`` (mean over envs of the summed
        reward x dt over their alive steps).
    """
    mask = alive.astype(bool)
    steps = max(int(mask.sum()), 1)
    rate = {name: float(step_rewards[..., k][mask].sum() / steps) for k, name in enumerate(names)}
    per_env = (step_rewards.sum(axis=-1) * mask).sum(axis=0) * dt
    return {
        "rate": rate,
        "total_rate": float(sum(rate.values())),
        "survival": float(mask[-1].mean()) if len(mask) else float("nan"),
        "return": float(per_env.mean()),
    }


def _rollout(env: Any, act: Any, sigma: float, command: tuple[float, float, float], steps: int, seed: int) -> Any:
    """One batch with noise ``sigma``: ``[T, W, K]`` step rewards and ``[T, W]`` alive-at-step-start."""
    import torch

    from gmloco.train.gate.rollout import _start

    commands = torch.tensor([command] * env.num_envs, dtype=torch.float32, device=env.device)
    obs = _start(env, commands)
    gen = torch.Generator(device=env.device).manual_seed(seed)
    alive = torch.ones(env.num_envs, dtype=torch.bool, device=env.device)
    rewards, alive_trace = [], []
    for _ in range(steps):
        actions, _ = act(obs)
        noise = torch.randn(actions.shape, generator=gen, device=actions.device) * sigma
        alive_trace.append(alive.clone())
        obs, _, terminated, _, _ = env.step(actions + noise)
        rewards.append(env.reward_manager._step_reward.clone())
        alive &= ~terminated
    return torch.stack(rewards).cpu().numpy(), torch.stack(alive_trace).cpu().numpy()


def run_noise_cost(cfg: NoiseCostCfg) -> dict[str, Any]:
    """Roll ``cfg.policy_dir`` out at each noise level; return the per-level rates (see :func:`noise_rates`)."""
    import torch
    from tqdm import tqdm

    import gmloco.contact as gc
    from gmloco.train.evaluation_ts import _pin_materials
    from gmloco.train.gate.config import GateCfg
    from gmloco.train.gate.policy import GateInputError, read_policy
    from gmloco.train.gate.rollout import _checkpoint_actor

    t0 = time.monotonic()
    policy = read_policy(cfg.policy_dir)
    floor = GateCfg().floor
    if cfg.floor_depth is not None:
        floor = replace(floor, enabled=True, depth_range=(cfg.floor_depth, cfg.floor_depth))
    gate = GateCfg(
        policy_dir=cfg.policy_dir,
        materials=(cfg.material,),
        speeds=(cfg.speed,),
        contact_model=cfg.contact_model,
        num_envs=cfg.num_envs,
        device=cfg.device,
        seed=cfg.seed,
        duration_s=cfg.seconds,
        floor=floor,
    )
    if policy.kind == "ppo":
        raise GateInputError(f"{cfg.policy_dir}: the study needs a teacher or student checkpoint, not an ONNX export")
    env, act = _checkpoint_actor(gate, policy)
    material = gc.MATERIAL_PRESETS[cfg.material]
    n = env.num_envs
    names = list(env.reward_manager.active_terms)
    steps = round(cfg.seconds / env.step_dt)
    levels = {}
    try:
        for i, sigma in enumerate(tqdm(cfg.noise_stds, desc="noise levels", unit="level")):
            _pin_materials(env, [material.rho_c] * n, [material.mu_int] * n, [material.mu_surf] * n)
            with torch.no_grad():
                rewards, alive = _rollout(env, act, sigma, (cfg.speed, 0.0, 0.0), steps, cfg.seed + i)
            levels[f"{sigma:g}"] = noise_rates(rewards, alive, names, env.step_dt)
    finally:
        env.close()
    return {
        "policy": cfg.policy_dir,
        "actor": policy.kind,
        "levels": levels,
        "terms": names,
        "setup": {"cfg": asdict(cfg), "step_dt": env.step_dt, "steps": steps, "wall_s": time.monotonic() - t0},
    }


def plot_noise_cost(doc: dict[str, Any], path: str, marks: Sequence[float] = ()) -> None:
    """Figure: the reward rate against the noise std, and the terms that lose most between the extreme stds.

    Args:
        doc: A :func:`run_noise_cost` result.
        path: PNG to write.
        marks: Stds to mark with a dotted line (e.g. the action stds a training run reached).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    levels = doc["levels"]
    sigma = [float(s) for s in levels]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1, 1.4]})
    left.plot(sigma, [levels[s]["total_rate"] for s in levels], "o-")
    for m in marks:
        left.axvline(m, ls=":", c="gray")
    left.set_xlabel("noise std per action dimension [policy action units]")
    left.set_ylabel("reward rate over alive steps [1/s]")
    left.set_title("All terms")
    names = list(levels)
    first, last = names[0], names[-1]
    delta = {t: levels[last]["rate"][t] - levels[first]["rate"][t] for t in doc["terms"]}
    worst = sorted(delta, key=delta.__getitem__)[:10]
    right.barh(range(len(worst)), [delta[t] for t in worst])
    right.set_yticks(range(len(worst)), worst, fontsize=8)
    right.invert_yaxis()
    right.set_xlabel(f"rate at std {last} minus rate at std {first} [1/s]")
    right.set_title("The ten terms that lose most")
    cfg = doc["setup"]["cfg"]
    floor = "the deep bed" if cfg["floor_depth"] is None else f"a {100 * cfg['floor_depth']:g} cm floor"
    fig.suptitle(
        f"What the rewards charge for action noise: {doc['policy']}, {cfg['material']} ({cfg['contact_model']}) "
        f"over {floor}, {cfg['speed']:g} m/s",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _floats(text: str) -> tuple[float, ...]:
    """Parse ``"0,0.5,1.0"`` into non-negative numbers."""
    try:
        values = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected comma-separated numbers >= 0, e.g. 0,0.5,1.0") from None
    if not values or min(values) < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: expected comma-separated numbers >= 0, e.g. 0,0.5,1.0")
    return values


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: run the study, print and write its JSON; bad input exits 2."""
    from gmloco.contact import MATERIAL_PRESETS
    from gmloco.train.gate.policy import GateInputError
    from gmloco.train.gate.run import write_json

    d = NoiseCostCfg()
    p = argparse.ArgumentParser(
        prog="python -m gmloco.train.studies.noise_cost", description=(__doc__ or "").splitlines()[0]
    )
    p.add_argument("--policy", default=d.policy_dir, help="run folder of a teacher or student checkpoint")
    p.add_argument("--out", required=True, help="summary JSON")
    p.add_argument("--noise-stds", type=_floats, default=d.noise_stds, help="noise std per action dimension")
    p.add_argument("--material", choices=sorted(MATERIAL_PRESETS), default=d.material)
    p.add_argument("--speed", type=float, default=d.speed, help="held forward command [m/s]")
    p.add_argument("--floor-depth", type=float, default=d.floor_depth, help="hard floor depth [m]; <= 0: none")
    p.add_argument("--contact-model", default=d.contact_model, help="granular contact model")
    p.add_argument("--num-envs", type=int, default=d.num_envs)
    p.add_argument("--seconds", type=float, default=d.seconds, help="horizon [s]")
    p.add_argument("--device", default=d.device)
    p.add_argument("--seed", type=int, default=d.seed)
    p.add_argument("--figure", default=None, help="PNG of the rates against the noise std")
    p.add_argument("--mark", type=_floats, default=(), help="stds to mark in the figure, e.g. 0.86,1.22")
    p.add_argument(
        "--replot", action="store_true", help="no rollout: redraw --figure from the JSON at --out (written earlier)"
    )
    a = p.parse_args(argv)
    if a.replot:
        if a.figure is None:
            p.error("--replot needs --figure PATH")
        import json

        try:
            plot_noise_cost(json.loads(Path(a.out).read_text()), a.figure, a.mark)
        except (OSError, ValueError, KeyError) as err:
            print(f"noise_cost: cannot replot {a.out}: {err}; give the JSON this study wrote", file=sys.stderr)
            return 2
        return 0
    if a.num_envs < 1 or not a.seconds > 0:
        p.error(f"--num-envs {a.num_envs} --seconds {a.seconds}: give at least 1 env and a horizon > 0 s")
    from typing import get_args

    if a.contact_model not in get_args(ContactModelName):
        p.error(f"--contact-model {a.contact_model!r}: choose from {', '.join(get_args(ContactModelName))}")
    cfg = NoiseCostCfg(
        policy_dir=a.policy,
        noise_stds=a.noise_stds,
        material=a.material,
        speed=a.speed,
        floor_depth=a.floor_depth if a.floor_depth > 0 else None,
        contact_model=a.contact_model,
        num_envs=a.num_envs,
        seconds=a.seconds,
        device=a.device,
        seed=a.seed,
    )
    try:
        doc = run_noise_cost(cfg)
    except GateInputError as err:
        print(f"noise_cost: {err}", file=sys.stderr)
        return 2
    write_json(a.out, doc)
    if a.figure is not None:
        plot_noise_cost(doc, a.figure, a.mark)
    for sigma, level in doc["levels"].items():
        print(f"sigma {sigma}: return {level['return']:.2f}, survival {level['survival']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
