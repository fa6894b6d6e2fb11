# SPDX-License-Identifier: Apache-2.0
"""Whether the td student's heading drifts in the training simulator too (issue 9, the per-terrain runs).

On MPM basalt the student turned 35-69 degrees in 10 s under a zero yaw-rate command (``../../table_rows/per_terrain/README.md``).
This walks the same student (its ``StudentPPO`` checkpoint, whose ONNX export the MPM evaluation runs) in the
granular training simulator (3D-RFT on the whole foot box, as it was trained), with the MPM evaluation's commands:
(v, 0, 0) held for 10 s, v = 1.0 / 1.5 / 2.0 / 2.5 m/s, on basalt and dry sand, ``--repeats`` envs per cell, and
records each env's pelvis heading. Writes ``heading_ts.json`` beside this script.

    python benchmarks/mpm_eval/training_sim_checks/heading_drift/heading_ts.py [--repeats 2] [--device cpu]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/training_sim_checks/heading_drift"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
SPEEDS = (1.0, 1.5, 2.0, 2.5)
MATERIALS = ("basalt", "dry_sand")


def main() -> None:
    """Walk the student under the straight commands, report the heading turn per cell."""
    from gmloco.eval.metrics.locomotion import quat_wxyz_to_roll_pitch_yaw
    from gmloco.train.evaluation_ts import TsEvalCfg, pinned_walk

    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--repeats", type=int, default=2)
    p.add_argument("--device", default="cpu")
    p.add_argument("--duration", type=float, default=10.0)
    a = p.parse_args()
    cfg = TsEvalCfg(student_checkpoint="artifacts/gm_loco_student_td/checkpoint.pt",
                    teacher_checkpoint="artifacts/gm_loco_teacher_td/checkpoint.pt", foot_faces="box",
                    baseline_policy=None, device=a.device)  # fmt: skip
    cells = [(m, v) for m in MATERIALS for v in SPEEDS for _ in range(a.repeats)]
    walk = pinned_walk(cfg, [m for m, _ in cells], [(v, 0.0, 0.0) for _, v in cells], a.duration)
    yaw = np.unwrap(quat_wxyz_to_roll_pitch_yaw(walk["quat_wxyz"])[..., 2], axis=0)
    live, dt = walk["alive"], walk["dt"]
    rows = []
    for w, (m, v) in enumerate(cells):
        t_alive = int(live[:, w].sum())
        turn = np.degrees(yaw[:t_alive, w] - yaw[0, w])
        rows.append({"material": m, "speed": v, "alive_s": t_alive * dt,
                     "heading_turn_max_deg": float(np.max(np.abs(turn))) if t_alive else float("nan"),
                     "heading_turn_end_deg": float(turn[-1]) if t_alive else float("nan")})  # fmt: skip
    doc = {"policy": cfg.student_checkpoint, "simulator": "granular training simulator (3D-RFT, whole foot box)",
           "device": a.device, "duration_s": a.duration, "wall_s": round(walk["wall_s"], 1), "rows": rows}  # fmt: skip
    (HERE / "heading_ts.json").write_text(json.dumps(doc, indent=1) + "\n")
    for r in rows:
        print(f"{r['material']:9s} v={r['speed']:.1f}: alive {r['alive_s']:.1f} s, largest turn "
              f"{r['heading_turn_max_deg']:.1f} deg, at the end {r['heading_turn_end_deg']:+.1f} deg")  # fmt: skip


if __name__ == "__main__":
    main()
