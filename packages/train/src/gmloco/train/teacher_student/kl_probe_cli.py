# SPDX-License-Identifier: Apache-2.0
"""Command line of the policy-KL probes on a committed teacher, at CPU scale (exit 2 on bad input).

Example: ``python -m gmloco.train.teacher_student.kl_probe_cli --artifact artifacts/gm_loco_teacher_yaw
--num-envs 32``. Builds the teacher's env from the artifact's ``train_cfg`` (``summary.json`` or
``train_cfg.json``), loads its ``checkpoint.pt``, runs ``--warm`` ordinary iterations (logging the KL and
rate the schedule sees at each mini-batch), fills one more rollout and prints the probes of
:mod:`gmloco.train.teacher_student.kl_probe` as JSON.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from gmloco.train.teacher_student.kl_probe import PARAM_GROUPS

STEPPED = (("policy",), ("encoder",), ("decoder",), ("policy", "encoder"), PARAM_GROUPS)
"""Parameter-group selections stepped by the probe."""


def _parse(argv: Sequence[str] | None) -> argparse.Namespace:
    """Parse the command line."""
    p = argparse.ArgumentParser(prog="python -m gmloco.train.teacher_student.kl_probe_cli", description=__doc__)
    p.add_argument("--artifact", type=Path, required=True, help="teacher folder with checkpoint.pt + train_cfg")
    p.add_argument("--num-envs", type=int, default=32)
    p.add_argument("--steps", type=int, default=24, help="env steps per env and rollout")
    p.add_argument("--warm", type=int, default=2, help="ordinary iterations before the probes")
    p.add_argument("--lrs", type=float, nargs="+", default=[1e-4, 1e-3], help="rates of the stepped probes")
    p.add_argument("--probe-steps", type=int, default=8, help="mini-batch steps of each stepped probe")
    p.add_argument("--device", default="cpu")
    args = p.parse_args(argv)
    if min(args.num_envs, args.steps, args.probe_steps) < 1 or args.warm < 0 or min(args.lrs) < 0.0:
        p.error("--num-envs, --steps, --probe-steps must be >= 1, --warm >= 0, --lrs >= 0")
    return args


def _fail(message: str) -> None:
    """Print ``message`` to stderr and exit with status 2 (bad input)."""
    print(f"kl_probe: {message}", file=sys.stderr)
    sys.exit(2)


def _train_cfg(folder: Path) -> dict[str, Any]:
    """The artifact's training config; exit 2 if there is none or no checkpoint."""
    summary, plain = folder / "summary.json", folder / "train_cfg.json"
    if not (folder / "checkpoint.pt").is_file():
        _fail(f"{folder / 'checkpoint.pt'} not found")
    if summary.is_file() and "train_cfg" in (doc := json.loads(summary.read_text())):
        return doc["train_cfg"]
    if plain.is_file():
        return json.loads(plain.read_text())
    _fail(f"{folder} has neither summary.json with a train_cfg nor train_cfg.json")
    raise AssertionError  # unreachable: _fail exits


def _runner(args: argparse.Namespace, tc: dict[str, Any]) -> Any:
    """Env + runner of the artifact at probe scale, checkpoint loaded."""
    from gmloco.train import TrainRunCfg
    from gmloco.train.config import GranularTaskCfg
    from gmloco.train.tasks.g1_granular.upgrade_metadata import task_from_dict
    from gmloco.train.training import _make_env, _make_runner

    defaults = asdict(GranularTaskCfg())  # fields added after the run, at their defaults
    task = task_from_dict(tc["task"], {k: v for k, v in defaults.items() if k not in tc["task"]})
    cfg = TrainRunCfg(task=task, num_envs=args.num_envs, device=args.device, num_steps_per_env=args.steps,
                      export_onnx=False, rsl_rl_overrides=tc["rsl_rl_overrides"], history_length=tc["history_length"],
                      run_dir=tempfile.mkdtemp(prefix="kl_probe_"))  # fmt: skip
    env = _make_env(cfg)
    runner = _make_runner(cfg, env, Path(cfg.run_dir))
    runner.load(str(args.artifact / "checkpoint.pt"))
    return runner


def _rollout(runner: Any, obs: Any, steps: int) -> Any:
    """Fill the storage as the runner does; return the last observation."""
    import torch

    alg = runner.alg
    with torch.inference_mode():
        for _ in range(steps):
            obs, rew, dones, extras = runner.env.step(alg.act(obs))
            alg.process_env_step(obs, rew, dones, extras)
        alg.compute_returns(obs)
    return obs


def _warm(runner: Any, obs: Any, iterations: int, steps: int) -> tuple[Any, list[dict[str, Any]]]:
    """Ordinary iterations; per iteration the (KL, rate) the schedule saw at each mini-batch."""
    alg, log = runner.alg, []
    adapt = alg._adapt_learning_rate
    seen: list[tuple[float, float]] = []

    def spy(batch: Any) -> None:
        seen.append((_batch_kl(alg, batch), alg.learning_rate))
        adapt(batch)

    alg._adapt_learning_rate = spy
    for _ in range(iterations):
        seen.clear()
        obs = _rollout(runner, obs, steps)
        alg.update()
        log.append({"kl": [k for k, _ in seen], "lr": [r for _, r in seen], "lr_end": alg.learning_rate})
    alg._adapt_learning_rate = adapt
    return obs, log


def _batch_kl(alg: Any, batch: Any) -> float:
    """KL of the forward pass just run against the stored distribution."""
    import torch

    with torch.inference_mode():
        old, new = batch.old_distribution_params, alg.actor.output_distribution_params
        return float(alg.actor.get_kl_divergence(old, new).mean())


def main(argv: Sequence[str] | None = None) -> dict[str, Any]:
    """Run the probes and print them as JSON; return the result."""
    from gmloco.train.teacher_student.kl_probe import (
        grad_norms_by_loss,
        kl_stepping_only,
        std_gradients_by_loss,
        zero_step_kls,
    )

    args = _parse(argv)
    tc = _train_cfg(args.artifact)
    with contextlib.redirect_stdout(sys.stderr):  # rsl-rl prints the models; stdout carries only the JSON
        runner = _runner(args, tc)
    alg = runner.alg
    alg.train_mode()
    obs, warm = _warm(runner, runner.env.get_observations(), args.warm, args.steps)
    _rollout(runner, obs, args.steps)
    first = next(iter(alg.storage.mini_batch_generator(alg.num_mini_batches, 1)))
    out: dict[str, Any] = {
        "artifact": str(args.artifact),
        "num_envs": args.num_envs,
        "warm_iterations": warm,
        "zero_step_kl": zero_step_kls(alg),
        "grad_norms_first_minibatch": grad_norms_by_loss(alg, first),
        "std_gradient_by_loss": std_gradients_by_loss(alg),
        "kl_stepping_only": {
            f"lr={lr:g} {'+'.join(sel)}": kl_stepping_only(alg, sel, lr, args.probe_steps)
            for lr in args.lrs
            for sel in STEPPED
        },
    }
    print(json.dumps(out, indent=1))
    return out


if __name__ == "__main__":
    main()
