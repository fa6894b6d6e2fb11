# SPDX-License-Identifier: Apache-2.0
"""Whether the td student's heading drifts in the training simulator too (issue 9, session 16).

On MPM basalt the student turned 35-69 degrees in 10 s under a zero yaw-rate command (``../gpu_s16/README.md``).
This walks the same student (its ``StudentPPO`` checkpoint, whose ONNX export the MPM evaluation runs) in the
granular training simulator (3D-RFT on the whole foot box, as it was trained), with the MPM evaluation's commands:
(v, 0, 0) held for 10 s, v = 1.0 / 1.5 / 2.0 / 2.5 m/s, on basalt and dry sand, ``--repeats`` envs per cell, and
records each env's pelvis heading. Writes ``heading_ts.json`` beside this script.

    python results/mpm_eval/cpu_s16/heading_ts.py [--repeats 2] [--device cpu]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch

HERE = Path(__file__).resolve().parent
SPEEDS = (1.0, 1.5, 2.0, 2.5)
MATERIALS = ("basalt", "dry_sand")


def main() -> None:
    """Build the play env, pin materials and commands, walk 10 s, report the heading turn per cell."""
    from tensordict import TensorDict

    from gmloco.contact import MATERIAL_PRESETS
    from gmloco.eval.metrics.locomotion import quat_wxyz_to_roll_pitch_yaw
    from gmloco.train.evaluation_ts import TsEvalCfg, _build_runner, _pin_materials, _policy_step, _start

    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--repeats", type=int, default=2)
    p.add_argument("--device", default="cpu")
    p.add_argument("--duration", type=float, default=10.0)
    a = p.parse_args()
    cfg = TsEvalCfg(student_checkpoint="artifacts/gm_loco_student_td/checkpoint.pt",
                    teacher_checkpoint="artifacts/gm_loco_teacher_td/checkpoint.pt", foot_faces="box",
                    baseline_policy=None, device=a.device)  # fmt: skip
    cells = [(m, v) for m in MATERIALS for v in SPEEDS for _ in range(a.repeats)]
    t0 = time.perf_counter()
    runner = _build_runner(cfg, len(cells), a.duration)
    env = runner.env.unwrapped
    mats = [MATERIAL_PRESETS[m] for m, _ in cells]
    _pin_materials(env, [x.rho_c for x in mats], [x.mu_int for x in mats], [x.mu_surf for x in mats])
    commands = torch.tensor([[v, 0.0, 0.0] for _, v in cells], dtype=torch.float32, device=env.device)
    runner.alg.eval_mode()
    obs = _start(runner, commands)
    robot = env.scene["robot"]
    alive = torch.ones(len(cells), dtype=torch.bool, device=env.device)
    quats, alives = [], []
    for _ in range(round(a.duration / env.step_dt)):
        quats.append(robot.data.root_link_quat_w.clone())  # w x y z
        alives.append(alive.clone())
        out = _policy_step(runner, obs)
        obs_dict, _, terminated, _, _ = env.step(out["actions"])
        obs = TensorDict(obs_dict, batch_size=[len(cells)])
        alive &= ~terminated
    yaw = np.unwrap(quat_wxyz_to_roll_pitch_yaw(torch.stack(quats).cpu().numpy())[..., 2], axis=0)
    live = torch.stack(alives).cpu().numpy()
    rows = []
    for w, (m, v) in enumerate(cells):
        t_alive = int(live[:, w].sum())
        turn = np.degrees(yaw[:t_alive, w] - yaw[0, w])
        rows.append({"material": m, "speed": v, "alive_s": t_alive * env.step_dt,
                     "heading_turn_max_deg": float(np.max(np.abs(turn))) if t_alive else float("nan"),
                     "heading_turn_end_deg": float(turn[-1]) if t_alive else float("nan")})  # fmt: skip
    doc = {"policy": cfg.student_checkpoint, "simulator": "granular training simulator (3D-RFT, whole foot box)",
           "device": a.device, "duration_s": a.duration, "wall_s": round(time.perf_counter() - t0, 1), "rows": rows}  # fmt: skip
    (HERE / "heading_ts.json").write_text(json.dumps(doc, indent=1) + "\n")
    for r in rows:
        print(f"{r['material']:9s} v={r['speed']:.1f}: alive {r['alive_s']:.1f} s, largest turn "
              f"{r['heading_turn_max_deg']:.1f} deg, at the end {r['heading_turn_end_deg']:+.1f} deg")  # fmt: skip


if __name__ == "__main__":
    main()
