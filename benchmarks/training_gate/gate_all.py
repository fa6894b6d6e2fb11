# SPDX-License-Identifier: Apache-2.0
"""Run the training gate on the delivered student and the paper's baselines; write results/training_gate/.

    uv run python benchmarks/training_gate/gate_all.py --device cuda:0 --num-envs 1024

Writes ``results/training_gate/summary.json`` (the delivered student, ``--student``) and ``<run>.json`` for every
run of ``--runs`` (default: the delivered teacher and the PPO-3D-RFT and PPO-Rigid baselines), then
``table.md``: one row per run, the pass of each key. ``--episodes``, ``--seconds`` and ``--num-envs`` scale it down
for a CPU check; a run folder that cannot be gated stops the script with exit 2.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

KEYS = ("success_pct", "vel_error_mps", "yaw_rate_ratio", "heading_drift_deg", "circle_dtw_m", "swing_apex_cm",
        "eta_r2_heldout", "gpu_minutes")  # fmt: skip
"""The gate's keys, in the issue's order."""


def _table(rows: dict[str, dict[str, Any]]) -> str:
    """Markdown table: run, actor, episodes per cell, episode length, then pass / fail per key and overall."""
    head = "| run | actor | episodes/cell | episode [s] | " + " | ".join(KEYS) + " | all |"
    lines = [head, "|" + "---|" * (len(KEYS) + 5)]
    for run, s in rows.items():
        verdict = " | ".join("pass" if s["pass"][k] else "fail" for k in (*KEYS, "all"))
        setup = s["setup"]
        lines.append(f"| {run} | {s['actor']} | {setup['episodes_per_cell']} | {setup['episode_s']:g} | {verdict} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Gate every run; return the exit code."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--student", default="artifacts/gm_loco_student_td", help="the delivered student's run folder")
    p.add_argument("--runs", nargs="*", default=["artifacts/gm_loco_teacher_td", "artifacts/ppo_rft3d",
                                                 "artifacts/ppo_rigid"])  # fmt: skip
    p.add_argument("--out", type=Path, default=Path("results/training_gate"))
    p.add_argument("--episodes", type=int, default=20)
    p.add_argument("--seconds", type=float, default=10.0)
    p.add_argument("--num-envs", type=int, default=1024)
    p.add_argument("--device", default="cuda:0")
    args = p.parse_args(argv)
    from gmloco.train.gate import GateCfg, run_gate
    from gmloco.train.gate.policy import GateInputError

    rows: dict[str, dict[str, Any]] = {}
    for folder in [args.student, *args.runs]:
        name = "summary" if folder == args.student else Path(folder).name
        cfg = GateCfg(policy_dir=folder, repeats=args.episodes, duration_s=args.seconds, num_envs=args.num_envs,
                      device=args.device, out_path=str(args.out / f"{name}.json"))  # fmt: skip
        try:
            rows[Path(folder).name] = run_gate(cfg)
        except GateInputError as err:
            print(f"gate_all: {err}", file=sys.stderr)
            return 2
        print(f"{folder}: all {'pass' if rows[Path(folder).name]['pass']['all'] else 'fail'}")
    tmp = args.out / ".table.md.tmp"
    tmp.write_text(_table(rows))
    tmp.replace(args.out / "table.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
