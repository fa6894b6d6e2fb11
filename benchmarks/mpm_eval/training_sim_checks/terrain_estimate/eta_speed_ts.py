# SPDX-License-Identifier: Apache-2.0
"""Issue 9: does the td student's decoded stiffness depend on the commanded speed in its own training simulator?

On MPM's transition course (``../../table_rows/transition_course/README.md``) the student's decoded eta fell with the commanded speed more
than it differed between basalt and dry sand. This walks the same student (its ``StudentPPO`` checkpoint, whose ONNX
export the MPM evaluation runs) straight ahead, (v, 0, 0) held for 10 s, v = 1.0 / 1.5 / 2.0 / 2.5 m/s, in the
granular training simulator (3D-RFT on the whole foot box, as it was trained) on basalt, dry sand and poppy seed
pinned, ``--repeats`` envs per cell. Per cell: the mean decoded eta of the student and of its frozen teacher over
the alive steps after ``--warmup`` s (and the student's over the first 3 s, warm-up included, as the MPM records
average it), the true eta, the time alive. Beside them the MPM runs' decoded eta per
speed, from the committed episode records: the transition course per layer (the transition-course runs) and the single-material
rows (basalt, poppy seed: the per-terrain runs; dry sand: the ablation-circle runs). Writes ``eta_speed_ts.json`` and
``fig_eta_speed.png`` beside this script.

    python benchmarks/mpm_eval/training_sim_checks/terrain_estimate/eta_speed_ts.py [--repeats 3] [--device cpu]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/training_sim_checks/terrain_estimate"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
MPM = HERE.parents[1]
SPEEDS = (1.0, 1.5, 2.0, 2.5)
MATERIALS = ("basalt", "dry_sand", "poppy_seed")
MPM_ROWS = {"basalt": "table_rows/per_terrain/runs/table_td_basalt", "dry_sand": "table_rows/ablation_circles/runs/table_td_dry_sand_x4_share*",
            "poppy_seed": "table_rows/per_terrain/runs/table_td_poppy_seed"}  # fmt: skip
MPM_TRANSITION = "table_rows/transition_course/runs/table_td_transition_sq_share*"
EARLY_S = 3.0
"""The training simulator's early mean covers [0, EARLY_S) s, warm-up included, as the MPM records' means do [s]."""


def training_sim(repeats: int, device: str, duration: float, warmup: float) -> tuple[list[dict], float]:
    """Per (material, speed): decoded etas of student and teacher, the true eta, time alive (training simulator)."""
    from gmloco.train.evaluation_ts import TsEvalCfg, pinned_walk

    cfg = TsEvalCfg(student_checkpoint="artifacts/gm_loco_student_td/checkpoint.pt",
                    teacher_checkpoint="artifacts/gm_loco_teacher_td/checkpoint.pt", foot_faces="box",
                    baseline_policy=None, device=device)  # fmt: skip
    cells = [(m, v) for m in MATERIALS for v in SPEEDS for _ in range(repeats)]
    walk = pinned_walk(cfg, [m for m, _ in cells], [(v, 0.0, 0.0) for _, v in cells], duration)
    skip = round(warmup / walk["dt"])
    rows = []
    for m in MATERIALS:
        for v in SPEEDS:
            envs = [w for w, c in enumerate(cells) if c == (m, v)]
            mask = walk["alive"][skip:, envs]
            row = {"material": m, "speed": v, "envs": len(envs),
                   "alive_s": float(walk["alive"][:, envs].sum(axis=0).mean() * walk["dt"]),
                   "eta_true": float(walk["eta_true"][0, envs[0]])}  # fmt: skip
            for k in ("eta_student", "eta_teacher"):
                row[k] = float(walk[k][skip:, envs][mask].mean()) if mask.any() else float("nan")
            # as the MPM records average it: every alive step from the start, over the first EARLY_S seconds
            # (MPM's robots above 1.0 m/s fall after 1.5-6 s, so their means are mostly early steps)
            early = round(EARLY_S / walk["dt"])
            first = walk["alive"][:early, envs]
            row["eta_student_first_s"] = float(walk["eta_student"][:early, envs][first].mean())
            rows.append(row)
    return rows, float(walk["wall_s"])


def _episodes(pattern: str) -> list[dict]:
    return [json.loads(line) for d in sorted(MPM.glob(pattern)) for line in (d / "episodes.jsonl").open()]


def mpm_side() -> list[dict]:
    """Per (source, material, speed): the MPM runs' mean decoded eta (episode means), and the episodes counted."""
    rows = []
    for m, pattern in MPM_ROWS.items():
        eps = _episodes(pattern)
        for v in SPEEDS:
            vals = [e["eta_mean"] for e in eps if e["speed"] == v and np.isfinite(e.get("eta_mean", np.nan))]
            rows.append({"source": f"MPM {m} row", "material": m, "speed": v, "episodes": len(vals),
                         "eta_student": float(np.mean(vals)) if vals else float("nan")})  # fmt: skip
    eps = _episodes(MPM_TRANSITION)
    for m in MATERIALS:
        for v in SPEEDS:
            vals = [la["eta_mean"] for e in eps if e["speed"] == v for la in e["layers"] or []
                    if la["medium"] == m and la["steps"] > 0 and np.isfinite(la["eta_mean"])]  # fmt: skip
            rows.append({"source": "MPM transition layer", "material": m, "speed": v, "episodes": len(vals),
                         "eta_student": float(np.mean(vals)) if vals else float("nan")})  # fmt: skip
    return rows


def figure(ts: list[dict], mpm: list[dict], path: Path) -> None:
    """Decoded eta against commanded speed, a panel per material: training simulator vs MPM."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(MATERIALS), figsize=(13, 3.8), sharey=True, constrained_layout=True)
    for ax, m in zip(axes, MATERIALS, strict=True):
        rows = [r for r in ts if r["material"] == m]
        ax.plot(SPEEDS, [r["eta_student"] for r in rows], "o-", color="tab:blue", label="student, training sim")
        ax.plot(SPEEDS, [r["eta_teacher"] for r in rows], "s:", color="tab:blue", alpha=0.6,
                label="teacher, training sim")  # fmt: skip
        ax.plot(SPEEDS, [r["eta_student_first_s"] for r in rows], "x-.", color="tab:blue", alpha=0.6,
                label=f"student, training sim, first {EARLY_S:g} s")  # fmt: skip
        ax.axhline(rows[0]["eta_true"], color="k", lw=1, ls="--", label="true eta (training sim)")
        for source, style in (("MPM transition layer", "o-"), (f"MPM {m} row", "^--")):
            pts = [r for r in mpm if r["source"] == source and r["material"] == m]
            ax.plot(SPEEDS, [r["eta_student"] for r in pts], style, color="tab:red", alpha=0.8,
                    label=f"student, {source.replace(m + ' ', '')}")  # fmt: skip
        ax.set(title=m, xlabel="commanded speed [m/s]")
    axes[0].set_ylabel("decoded stiffness eta [-] (mean over alive steps)")
    axes[0].legend(fontsize=7)
    fig.suptitle("td student's decoded stiffness by commanded speed: its training simulator vs MPM sand", fontsize=9)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    """Walk the student in the training simulator, read the MPM records, write the JSON and the figure."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--device", default="cpu")
    p.add_argument("--duration", type=float, default=10.0)
    p.add_argument("--warmup", type=float, default=1.0, help="seconds left out at the start (history filling)")
    a = p.parse_args()
    ts, wall = training_sim(a.repeats, a.device, a.duration, a.warmup)
    mpm = mpm_side()
    doc = {"policy": "artifacts/gm_loco_student_td/checkpoint.pt (ONNX export: policy.onnx)",
           "training_sim": "granular training simulator (3D-RFT, whole foot box), materials pinned",
           "command": f"(v, 0, 0) for {a.duration} s", "warmup_s": a.warmup, "device": a.device,
           "wall_s": round(wall, 1), "training_sim_rows": ts, "mpm_rows": mpm}  # fmt: skip
    (HERE / "eta_speed_ts.json").write_text(json.dumps(doc, indent=1) + "\n")
    figure(ts, mpm, HERE / "fig_eta_speed.png")
    for r in ts:
        print(f"sim {r['material']:10s} v={r['speed']:.1f}: student {r['eta_student']:.3f} (first {EARLY_S:g} s "
              f"{r['eta_student_first_s']:.3f}), teacher {r['eta_teacher']:.3f}, true {r['eta_true']:.3f}, "
              f"alive {r['alive_s']:.1f} s")  # fmt: skip
    for r in mpm:
        print(f"{r['source']:22s} {r['material']:10s} v={r['speed']:.1f}: {r['eta_student']:.3f} ({r['episodes']})")


if __name__ == "__main__":
    main()
