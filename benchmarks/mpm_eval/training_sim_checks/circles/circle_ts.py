# SPDX-License-Identifier: Apache-2.0
"""Whether the td student walks the commanded circle in the training simulator (issue 9, the rough-and-circles runs).

On MPM dry sand the student finished none of 75 circle episodes (``../../table_rows/rough_circles_lanes/README.md``). This walks the same
student (its ``StudentPPO`` checkpoint, whose ONNX export the MPM evaluation runs) in the granular training simulator
(3D-RFT on the whole foot box, as it was trained) with the MPM evaluation's circle command, (v, 0, v / R) with
R = 2 m held for 10 s, v = 1.0 / 1.5 / 2.0 / 2.5 m/s, on dry sand and basalt, ``--repeats`` envs per cell, and
scores each walk with the MPM evaluation's rules (:func:`gmloco.eval.g1.score.score_episode`'s progress rule and
:mod:`gmloco.eval.metrics.locomotion`): course finished, DTW path error, mean yaw-rate error, the heading's turn.
Writes ``circle_ts.json`` beside this script.

    python benchmarks/mpm_eval/training_sim_checks/circles/circle_ts.py [--repeats 2] [--device cpu]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/training_sim_checks/circles"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
SPEEDS = (1.0, 1.5, 2.0, 2.5)
MATERIALS = ("dry_sand", "basalt")
RADIUS_M = 2.0
COURSE_SLACK = 0.2


def main() -> None:
    """Walk the student under the circle commands, score each env's circle."""
    from gmloco.eval.metrics.locomotion import (
        circular_path,
        course_finished_at,
        metric_path_error,
        quat_wxyz_to_roll_pitch_yaw,
    )
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
    walk = pinned_walk(cfg, [m for m, _ in cells], [(v, 0.0, v / RADIUS_M) for _, v in cells], a.duration)
    dt, xy, wz, live = walk["dt"], walk["xy"], walk["wz"], walk["alive"]
    yaw = np.unwrap(quat_wxyz_to_roll_pitch_yaw(walk["quat_wxyz"])[..., 2], axis=0)
    rows = []
    for w, (m, v) in enumerate(cells):
        n = int(live[:, w].sum())
        cmd_xy, _ = circular_path(v, v / RADIUS_M, a.duration, dt, start_xy=tuple(xy[0, w]), start_yaw=yaw[0, w])
        fin = course_finished_at(xy[:n, w], cmd_xy, dt, COURSE_SLACK)
        rows.append({"material": m, "speed": v, "alive_s": n * dt, "finished_at_s": fin,
                     "success": bool(n == len(xy) and fin is not None) or (fin is not None and fin <= n * dt),
                     "path_error_m": metric_path_error(xy[:n, w], cmd_xy) if n else float("nan"),
                     "yaw_rate_cmd": v / RADIUS_M, "yaw_rate_mean": float(np.mean(wz[:n, w])) if n else float("nan"),
                     "yaw_error": float(np.mean(np.abs(wz[:n, w] - v / RADIUS_M))) if n else float("nan"),
                     "heading_turn_end_deg": float(np.degrees(yaw[n - 1, w] - yaw[0, w])) if n else float("nan"),
                     "heading_turn_cmd_deg": float(np.degrees(v / RADIUS_M * n * dt))})  # fmt: skip
    doc = {"policy": cfg.student_checkpoint, "simulator": "granular training simulator (3D-RFT, whole foot box)",
           "command": f"(v, 0, v / {RADIUS_M}) for {a.duration} s", "device": a.device, "duration_s": a.duration,
           "wall_s": round(walk["wall_s"], 1), "rows": rows}  # fmt: skip
    (HERE / "circle_ts.json").write_text(json.dumps(doc, indent=1) + "\n")
    for r in rows:
        print(f"{r['material']:9s} v={r['speed']:.1f}: alive {r['alive_s']:.1f} s, finished {r['finished_at_s']}, "
              f"path error {r['path_error_m']:.2f} m, yaw rate {r['yaw_rate_mean']:.2f} of {r['yaw_rate_cmd']:.2f} "
              f"rad/s, turned {r['heading_turn_end_deg']:.0f} of {r['heading_turn_cmd_deg']:.0f} deg")  # fmt: skip


if __name__ == "__main__":
    main()
