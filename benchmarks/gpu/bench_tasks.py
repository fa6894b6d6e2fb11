"""Side-by-side throughput of mjlab tasks on one GPU: bare simulator step rate and PPO iteration time.

Runs every task in one process so the numbers compare (same device, same driver, same warm-up):

    python benchmarks/gpu/bench_tasks.py --tasks Mjlab-Velocity-Flat-Unitree-G1 Gmloco-Velocity-Granular-G1 \
        --import gmloco.train.tasks.registry --num-envs 4096 --iterations 40 --out $OUT/bench.json

For each task it reports
* ``sim_physics_steps_per_s``: ``env.sim.step()`` (one physics substep for every world, CUDA graph) timed
  over many calls, i.e. the simulator's ceiling without managers, observations or the policy;
* ``ppo_env_steps_per_s``, ``ppo_s_per_iteration``, ``ppo_collection_s``, ``ppo_learning_s``: medians over
  the PPO iterations after the first ``--warmup`` ones, read from rsl-rl's own timers.

Project tasks register themselves when their registry is imported (``--import gmloco.train.tasks.registry``);
unknown task ids stop the script before the first env build.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import statistics
import sys
import tempfile
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any


def _parse() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tasks", nargs="+", default=["Mjlab-Velocity-Flat-Unitree-G1"])
    p.add_argument("--import", dest="imports", nargs="*", default=[], help="modules that register tasks")
    p.add_argument("--num-envs", type=int, default=4096)
    p.add_argument("--iterations", type=int, default=40, help="PPO iterations per task")
    p.add_argument("--warmup", type=int, default=5, help="PPO iterations left out of the medians")
    p.add_argument("--sim-steps", type=int, default=400, help="physics substeps timed for the sim rate")
    p.add_argument(
        "--uniform-action-scale",
        type=float,
        default=None,
        help="replace the task's joint-position action scale by this one value for every joint [rad] (A/B of the "
        "action scale; default: the task's own)",
    )
    p.add_argument("--entropy-coef", type=float, default=None, help="replace the PPO entropy bonus (default: task's)")
    p.add_argument(
        "--reward-weight",
        action="append",
        default=[],
        metavar="NAME=WEIGHT",
        help="replace one reward term's weight (repeatable; the term must exist in the task)",
    )
    p.add_argument("--device", default="cuda:0")
    p.add_argument("--out", type=Path, default=Path("bench.json"))
    return p.parse_args()


def _weights(items: list[str]) -> dict[str, float]:
    """``NAME=WEIGHT`` items as a dict (exit 2 on a malformed item)."""
    out: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        try:
            out[name] = float(value)
        except ValueError:
            sep = ""
        if not sep or not name:
            print(f"--reward-weight {item!r}: expected NAME=WEIGHT, e.g. action_rate_l2=-0.1", file=sys.stderr)
            sys.exit(2)
    return out


def _sync() -> None:
    import torch
    import warp as wp

    wp.synchronize()
    if torch.cuda.is_available():
        torch.cuda.synchronize()


def bench_sim(env: Any, steps: int) -> dict[str, float]:
    """Time bare physics substeps of an already built env [physics steps/s summed over worlds]."""
    for _ in range(20):
        env.sim.step()
    _sync()
    t0 = time.perf_counter()
    for _ in range(steps):
        env.sim.step()
    _sync()
    dt = time.perf_counter() - t0
    return {"sim_physics_steps_per_s": steps * env.num_envs / dt, "sim_s_per_substep": dt / steps}


def bench_ppo(
    task: str,
    num_envs: int,
    iterations: int,
    warmup: int,
    sim_steps: int,
    device: str,
    uniform_action_scale: float | None = None,
    entropy_coef: float | None = None,
    reward_weights: dict[str, float] | None = None,
) -> dict[str, Any]:
    """Build the task's env and runner as mjlab's train script does, then time PPO iterations.

    Besides the timers it records, per iteration, the learning rate the adaptive schedule left, the mean action
    std and the mean episode reward (``curve``), so the schedule's behaviour compares across tasks.
    """
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.rl import MjlabOnPolicyRunner, RslRlVecEnvWrapper
    from mjlab.tasks.registry import load_env_cfg, load_rl_cfg, load_runner_cls

    env_cfg = load_env_cfg(task)
    env_cfg.scene.num_envs = num_envs
    rl_cfg = load_rl_cfg(task)
    rl_cfg.logger = "tensorboard"
    if uniform_action_scale is not None:
        env_cfg.actions["joint_pos"].scale = uniform_action_scale  # type: ignore[attr-defined]
    if entropy_coef is not None:
        rl_cfg.algorithm.entropy_coef = entropy_coef
    for name, weight in (reward_weights or {}).items():
        if name not in env_cfg.rewards:
            print(
                f"--reward-weight {name}: no such reward term in {task}; terms: {sorted(env_cfg.rewards)}",
                file=sys.stderr,
            )
            sys.exit(2)
        env_cfg.rewards[name].weight = weight
    t_build = time.perf_counter()
    env = ManagerBasedRlEnv(cfg=env_cfg, device=device)
    build_s = time.perf_counter() - t_build
    sim = bench_sim(env, sim_steps)
    env.reset()
    wrapped = RslRlVecEnvWrapper(env, clip_actions=rl_cfg.clip_actions)
    runner_cls = load_runner_cls(task) or MjlabOnPolicyRunner
    log_dir = tempfile.mkdtemp(prefix="bench_")
    runner = runner_cls(wrapped, asdict(rl_cfg), log_dir, device)
    times: list[tuple[float, float]] = []
    rewards: list[float] = []
    curve: dict[str, list[float]] = {"learning_rate": [], "action_std": [], "mean_reward": []}
    original_log = runner.logger.log

    def _log(*args: Any, **kwargs: Any) -> None:  # record rsl-rl's own collection/learning timers
        times.append((kwargs["collect_time"], kwargs["learn_time"]))
        if len(runner.logger.rewbuffer) > 0:
            rewards.append(statistics.mean(runner.logger.rewbuffer))
        curve["learning_rate"].append(float(kwargs["learning_rate"]))
        curve["action_std"].append(float(kwargs["action_std"].mean().item()))
        curve["mean_reward"].append(rewards[-1] if rewards else float("nan"))
        original_log(*args, **kwargs)

    runner.logger.log = _log
    t0 = time.perf_counter()
    runner.learn(num_learning_iterations=iterations, init_at_random_ep_len=True)
    wall = time.perf_counter() - t0
    steady = times[warmup:] or times
    collect = statistics.median(t[0] for t in steady)
    learn = statistics.median(t[1] for t in steady)
    steps_per_iter = rl_cfg.num_steps_per_env * num_envs
    env.close()
    return {
        **sim,
        "build_s": build_s,
        "ppo_iterations": len(times),
        "ppo_wall_s": wall,
        "ppo_collection_s": collect,
        "ppo_learning_s": learn,
        "ppo_s_per_iteration": collect + learn,
        "ppo_env_steps_per_s": steps_per_iter / (collect + learn),
        "ppo_collection_env_steps_per_s": steps_per_iter / collect,
        "ppo_mean_reward_last": rewards[-1] if rewards else float("nan"),
        "num_steps_per_env": rl_cfg.num_steps_per_env,
        "uniform_action_scale": uniform_action_scale,
        "entropy_coef": rl_cfg.algorithm.entropy_coef,
        "reward_weights": {name: term.weight for name, term in env_cfg.rewards.items()},
        "curve": curve,
    }


def main() -> None:
    """Benchmark every requested task and write one JSON summary."""
    args = _parse()
    os.environ.setdefault("MUJOCO_GL", "disable")
    os.environ.setdefault("WANDB_MODE", "offline")
    import mjlab.tasks  # noqa: F401  (registers the stock tasks)
    import torch

    for mod in args.imports:
        importlib.import_module(mod)
    from mjlab.tasks.registry import list_tasks

    missing = [t for t in args.tasks if t not in list_tasks()]
    if missing:  # fail before the first (90 s) env build, not after it
        sys.exit(f"tasks not registered: {missing}; project tasks need --import gmloco.train.tasks.registry")
    results: dict[str, object] = {
        "device": torch.cuda.get_device_name(0) if torch.cuda.is_available() else "cpu",
        "num_envs": args.num_envs,
        "argv": sys.argv,
        "tasks": {},
    }
    for task in args.tasks:
        print(f"[bench] {task}", flush=True)
        results["tasks"][task] = bench_ppo(  # type: ignore[index]
            task,
            args.num_envs,
            args.iterations,
            args.warmup,
            args.sim_steps,
            args.device,
            args.uniform_action_scale,
            args.entropy_coef,
            _weights(args.reward_weight),
        )
        print(json.dumps(results["tasks"][task], indent=1), flush=True)  # type: ignore[index]
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(results, indent=1))
    print(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
