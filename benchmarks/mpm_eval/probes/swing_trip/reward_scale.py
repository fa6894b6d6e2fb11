# SPDX-License-Identifier: Apache-2.0
"""What each reward term pays per second on the clr50 teacher's gait, with ``foot_clearance="touchdown"`` on.

    uv run python benchmarks/mpm_eval/probes/swing_trip/reward_scale.py [sole|box]

The teacher (``artifacts/gm_loco_teacher_clr50``) walks 1.0 m/s on dry sand in the play env of
``gmloco.train.evaluation_ts`` (8 envs, CPU, 6 s; the first second left out), with the task's swing terms as the
next teacher run will have them: the L2 penalty at -50 plus the touchdown lift. Prints the mean per-second
reward of every term (dt-scaled, as training sees it), the touchdowns per second and their mean lift. Used to
set the lift term's weight (``rewards_cfg._clearance_term``).
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from typing import Any

import numpy as np
import torch

import gmloco.train.evaluation_ts as ets
import gmloco.train.tasks.g1_granular as g1_tasks

STEPS, WARMUP, ENVS = 300, 50, 8


def _with_touchdown(make_task: Any) -> Any:
    """Wrap the task factory that ``_build_runner`` calls so its task carries the next run's swing terms."""

    def make(*args: Any, **kwargs: Any) -> Any:
        task = make_task(*args, **kwargs)
        return replace(task, foot_clearance="touchdown", reward_weights={"foot_clearance_l2": -50.0})

    return make


def main(faces: str) -> dict[str, Any]:
    """Roll out and return the per-second rewards."""
    g1_tasks.g1_granular_task = _with_touchdown(g1_tasks.g1_granular_task)  # read by _build_runner at call time
    cfg = ets.TsEvalCfg(
        actor="teacher",
        teacher_checkpoint="artifacts/gm_loco_teacher_clr50/checkpoint.pt",
        baseline_policy=None,
        device="cpu",
        foot_faces=faces,  # type: ignore[arg-type]
    )
    runner = ets._build_runner(cfg, ENVS, 8.0)
    env = runner.env.unwrapped
    ets._pin_materials(env, [1500.0] * ENVS, [0.6] * ENVS, [0.4] * ENVS)  # dry sand
    obs = ets._start(runner, torch.tensor([[1.0, 0.0, 0.0]] * ENVS))
    rewards, names = env.reward_manager, env.reward_manager.active_terms
    sums, lifts = np.zeros(len(names)), []
    for t in range(STEPS):
        obs, _, _, _ = runner.env.step(ets._policy_step(runner, obs)["actions"])
        if t >= WARMUP:
            sums += rewards._step_reward.mean(dim=0).cpu().numpy() * env.step_dt
            feet = env.sand.feet
            lifts += feet.last_swing_lift[feet.first_contact].tolist()
    secs = (STEPS - WARMUP) * env.step_dt
    per_s = sorted(((n, float(v / secs)) for n, v in zip(names, sums, strict=True)), key=lambda kv: -abs(kv[1]))
    return {
        "faces": faces,
        "per_second": {n: round(v, 3) for n, v in per_s},
        "touchdowns_per_s_per_env": round(len(lifts) / secs / ENVS, 2),
        "touchdown_lift_mean_m": round(float(np.mean(lifts)), 4),
    }


if __name__ == "__main__":
    print(json.dumps(main(sys.argv[1] if len(sys.argv) > 1 else "sole"), indent=1))
