"""GPU check of the one-launch contact coupling: same rollout as the two-launch path, under CUDA graphs.

    python3 benchmarks/gpu/check_one_launch.py --num-envs 256 --steps 100 --out check.json

Builds the 3D-RFT G1 task twice (``ContactCoupling.one_launch`` True / False; the coupling is rebuilt before the
env's first step), steps both with the same fixed random actions and compares base positions, joint positions
and the contact state. A repeat of the two-launch rollout gives the run-to-run floor (GPU atomics). The CPU test (packages/train/tests/test_contact_coupling.py) covers the graph-less path;
this covers the step graph that the coupling re-captures.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import torch


def _rollout(one_launch: bool, num_envs: int, steps: int, device: str) -> dict[str, np.ndarray]:
    """Step the granular G1 task with fixed random actions; return qpos and the contact state arrays."""
    from mjlab.envs import ManagerBasedRlEnv

    from gmloco.train import g1_granular_task, make_g1_granular_env_cfg
    from gmloco.train.contact_coupling import ContactCoupling

    cfg = make_g1_granular_env_cfg(g1_granular_task("rft3d", play=True), num_envs)
    cfg.seed = 0
    env = ManagerBasedRlEnv(cfg=cfg, device=device)
    coupling: ContactCoupling = env.sand.coupling  # type: ignore[attr-defined]
    assert coupling.one_launch, "the training coupling should take the one-launch path"
    if not one_launch:  # rebuild the coupling on the two-launch path (restore the simulation's own methods)
        sim = env.sim
        sim.step = coupling._sim_step  # type: ignore[method-assign]
        sim.create_graph = coupling._sim_create_graph  # type: ignore[method-assign]
        coupling = ContactCoupling(coupling.model, sim, coupling.foot_bodyid.numpy().tolist(), True, False)
        coupling.install()
        env.sand.coupling = coupling  # type: ignore[attr-defined]
    env.reset()
    gen = torch.Generator(device="cpu").manual_seed(0)
    actions = 0.3 * torch.randn(steps, num_envs, env.action_manager.total_action_dim, generator=gen)
    for k in range(steps):
        env.step(actions[k].to(device))
    model = coupling.model
    out = {"qpos": env.sim.data.qpos.cpu().numpy()}
    out.update({n: getattr(model, n).numpy() for n in ("depth_max", "ema_tau", "vel_prev", "anchor")})
    env.close()
    return out


def main() -> int:
    """Run the three rollouts and write the differences."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--num-envs", type=int, default=256)
    p.add_argument("--steps", type=int, default=100, help="policy steps (4 substeps each)")
    p.add_argument("--device", default="cuda:0")
    p.add_argument("--out", type=Path, required=True)
    args = p.parse_args()
    one = _rollout(True, args.num_envs, args.steps, args.device)
    two = _rollout(False, args.num_envs, args.steps, args.device)
    again = _rollout(False, args.num_envs, args.steps, args.device)  # run-to-run floor of the two-launch path
    diff = {k: float(np.abs(one[k] - two[k]).max()) for k in one}
    floor = {k: float(np.abs(again[k] - two[k]).max()) for k in one}
    res = {
        "num_envs": args.num_envs,
        "steps": args.steps,
        "max_abs_diff_one_vs_two_launch": diff,
        "max_abs_diff_two_launch_repeat": floor,
        "depth_max_max": float(one["depth_max"].max()),
    }
    args.out.write_text(json.dumps(res, indent=1))
    print(json.dumps(res))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
