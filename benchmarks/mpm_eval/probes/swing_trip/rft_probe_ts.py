# SPDX-License-Identifier: Apache-2.0
"""The teacher-student policy in the TRAINING simulator, logged like the MPM probe (``policy_probe.py``).

    uv run python benchmarks/mpm_eval/probes/swing_trip/rft_probe_ts.py --faces sole --label student_clr50_rft3d_sole

``probes/dig_in_cpu/rft_probe.py`` plays mjlab ONNX exports; the student needs its history encoder, so this probe plays the
delivered student's checkpoint through ``gmloco.train.evaluation_ts`` (play env, deep dry sand, 1.0 m/s) and logs
``rft_probe.probe_row`` at every policy step: the same sole-box depths, pitch and sand force per foot. ``--faces``
picks the RFT collider (``GranularTaskCfg.foot_faces``). Appends one record per run to ``--log`` and prints
``policy_probe.swing_summary``, so the run sits beside the MPM probes in ``swing.py``.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import torch

import gmloco.train.evaluation_ts as ets
from gmloco.eval.g1.soles import SoleCfg
from gmloco.train.sand import FOOT_BODIES

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/probes/swing_trip"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""
MPM_EVAL_CODE = Path(__file__).resolve().parents[2]
"""``benchmarks/mpm_eval``: the sibling scripts this one loads."""

MPM_EVAL = RESULTS_HOME.parents[1]


def main() -> None:
    """Run one rollout, append its record, print the swing summary."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--student", default="artifacts/gm_loco_student_clr50/checkpoint.pt")
    p.add_argument("--faces", choices=["sole", "box"], default="sole")
    p.add_argument("--label", required=True)
    p.add_argument("--duration", type=float, default=3.0, help="simulated time [s]")
    p.add_argument("--log", type=Path, default=RESULTS_HOME / "rft_probe_ts.jsonl")
    args = p.parse_args()
    from swing import load_script  # this folder's table script, on sys.path when run as a script

    rft_probe = load_script("rft_probe", MPM_EVAL_CODE / "probes/dig_in_cpu/rft_probe.py")
    policy_probe = load_script("policy_probe", MPM_EVAL_CODE / "policy_probe.py")
    t0 = time.time()
    cfg = ets.TsEvalCfg(student_checkpoint=args.student, baseline_policy=None, device="cpu", foot_faces=args.faces)
    runner = ets._build_runner(cfg, 1, args.duration)
    env = runner.env.unwrapped
    ets._pin_materials(env, [1500.0], [0.6], [0.4])  # dry sand
    obs = ets._start(runner, torch.tensor([[1.0, 0.0, 0.0]]))
    robot = env.scene["robot"]
    foot_ids = [int(robot.indexing.body_ids[i]) for i in robot.find_bodies(FOOT_BODIES, preserve_order=True)[0]]
    sole, steps, rows, fell_at = SoleCfg(), round(args.duration / env.step_dt), [], None
    for k in range(steps + 1):
        rows.append(rft_probe.probe_row(env, foot_ids, sole, k * env.step_dt))
        if k == steps:
            break
        obs, _, dones, _ = runner.env.step(ets._policy_step(runner, obs)["actions"])
        if bool(dones[0]):
            fell_at = round((k + 1) * env.step_dt, 3)
            break
    swing = policy_probe.swing_summary(rows, fell_at)
    rec = {"label": args.label, "sim": f"mujoco+rft3d ({args.faces})", "policy": args.student, "material": "dry_sand",
           "vx_cmd": 1.0, "duration": args.duration, "first_fall_s": fell_at, **swing, "rows": rows,
           "s": round(time.time() - t0, 1)}  # fmt: skip
    with args.log.open("a") as f:
        f.write(json.dumps(rec) + "\n")
    print(args.label, {k: v for k, v in rec.items() if k != "rows"}, flush=True)


if __name__ == "__main__":
    main()
