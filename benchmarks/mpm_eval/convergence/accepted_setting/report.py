# SPDX-License-Identifier: Apache-2.0
"""The accepted-setting runs' convergence table, cost table and figure from ``runs/`` and ``sweep.jsonl`` (issue 9).

    python benchmarks/mpm_eval/convergence/accepted_setting/report.py   ->  report.md, fig_convergence.png, fig_cost.png, throughput.json

Every run: the td student (``artifacts/gm_loco_student_td``), MPM dry sand, 1.0 m/s straight, 8 robots in one
solver, 5 s episodes (one run 10 s), 0.6 m wide windows; they differ in voxel, rheology iterations, frame, bed depth
and window length (read from each run's summary.json). The reference is 3 cm / 1000 iterations / 1.8 m window.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/convergence/accepted_setting"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
REF = ("td_v0.03_it1000_dt0.005_r8_w18x06_d03_5s",)
# (label, device, runs pooled)
GROUPS = (
    ("R 3 cm / 1000 it, 5 ms, bed 30 cm, window 1.8 m", "H100", REF),
    ("3 cm / 500 it", "H100", ("td_v0.03_it500_dt0.005_r8_w18x06_d03_5s",)),
    ("3 cm / 350 it", "H200", ("td_v0.03_it350_d0.3_l1.8_r8_5s",)),
    ("3 cm / 250 it", "H100", ("td_v0.03_it250_dt0.005_r8_w18x06_d03_5s",)),
    ("4 cm / 500 it", "H200", ("td_v0.04_it500_d0.3_l1.8_r8_5s",)),
    ("5 cm / 1000 it", "H100", ("td_v0.05_it1000_dt0.005_r8_w18x06_d03_5s",)),
    ("3 cm / 1000 it, 10 ms frames x 2 rigid steps", "H100", ("td_v0.03_it1000_dt0.01_r8_w18x06_d03_5s",)),
    ("3 cm / 500 it, bed 20 cm", "H200", ("td_v0.03_it500_d0.2_l1.8_r8_5s",)),
    ("3 cm / 500 it, window 1.4 m (seeds 0, 1)", "H200",
     ("td_v0.03_it500_d0.3_l1.4_r8_5s", "td_v0.03_it500_d0.3_l1.4_r8_5s_seed1")),
)  # fmt: skip
LONG = "td_v0.03_it500_d0.3_l1.4_r8_10s"
"""The accepted setting with the paper's 10 s episodes."""


def load(names: tuple[str, ...]) -> list[dict]:
    """Episode rows of the pooled runs."""
    return [json.loads(line) for n in names for line in (HERE / "runs" / n / "episodes.jsonl").read_text().splitlines()]


def _row(label: str, dev: str, rows: list[dict], verdict: str) -> str:
    alive = np.array([r["alive_s"] for r in rows])
    return (f"| {label} | {dev} | {len(rows)} | {sum(r['success'] for r in rows)} | {int((alive < alive.max()).sum())} | "
            f"{100 * np.mean([r['mean_sinkage'] for r in rows]):.1f} | {100 * np.mean([r['max_sinkage'] for r in rows]):.1f} | "
            f"{np.median([r['vel_error'] for r in rows]):.3f} | {np.median([r['yaw_error'] for r in rows]):.3f} | "
            f"{sum(r['floor_reached'] for r in rows)} | {rows[0]['frames_per_s']:.2f} | {verdict} |")  # fmt: skip


def convergence_table() -> list[str]:
    """One row per setting, with ``gmloco.eval.studies.convergence``'s verdict against R."""
    from gmloco.eval.studies.convergence import compare_runs

    ref = load(REF)
    lines = ["| setting | GPU | episodes | success | falls (any time) | mean sinkage [cm] | max sinkage [cm] | velocity error "
             "median [m/s] | yaw error median [rad] | sole reached the floor | frames/s (8 robots) | against R |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for k, (label, dev, names) in enumerate(GROUPS):
        rows = load(names)
        if k == 0:
            lines.append(_row(label, dev, rows, "reference"))
            continue
        v = compare_runs(ref, rows)
        why = "; ".join(r.split(" (")[0] for r in v.reasons) if v.reasons else "no difference detected"
        lines.append(_row(label, dev, rows, f"**{v.decision}** ({why})"))
    long = load((LONG,))
    lines += ["", "The accepted setting with the paper's 10 s episodes:", "", lines[0], lines[1],
              _row("3 cm / 500 it, window 1.4 m, 10 s episodes", "H200", long, "-")]  # fmt: skip
    return lines


def cost_table() -> list[str]:
    """Cost cases: robots per solver, window, numerics; robot-frames per second and minutes per 100 episodes."""
    rows = [json.loads(line) for line in (HERE / "sweep.jsonl").read_text().splitlines()]
    rows.sort(key=lambda r: (r["device"], r["voxel_m"], -r["window_length_m"], r["robots"], r["rheology_solver"]))
    lines = ["| GPU | robots | window [m] | bed [m] | voxel [m] | iterations | rheology solver | particles | build [s] | "
             "frames/s | robot-frames/s | minutes per 100 ten-second episodes (stepping) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows:
        lines.append(
            f"| {r['device'].upper()} | {r['robots']} | {r['window_length_m']} x {r['window_width_m']} | "
            f"{r['bed_depth_m']} | {r['voxel_m']} | {r['iterations']} | {r['rheology_solver']} | {r['particles']:,} | "
            f"{r['build_s']:.0f} | {r['frames_per_s']:.2f} | {r['robot_frames_per_s']:.1f} | "
            f"{r['min_per_100_episodes_10s']:.0f} |"
        )
    return lines


def figure() -> None:
    """Sinkage and velocity error per episode for every setting, the reference's band shaded."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2), sharey=True)
    keys = (("mean_sinkage", 100.0, "mean sinkage of the lowest sole point [cm]"),
            ("vel_error", 1.0, "velocity tracking error [m/s]"), ("alive_s", 1.0, "time alive [s] (5 = whole episode)"))  # fmt: skip
    ref = load(REF)
    for a, (key, scale, name) in zip(ax, keys, strict=True):
        vals = [scale * r[key] for r in ref]
        a.axvspan(min(vals), max(vals), color="0.85", label="R: min-max")
        for k, (_, _, names) in enumerate(GROUPS):
            rows = load(names)
            jitter = np.random.default_rng(k).uniform(-0.15, 0.15, len(rows))
            a.scatter([scale * r[key] for r in rows], k + jitter, s=14)
        a.set_xlabel(name)
        a.grid(alpha=0.3)
    ax[0].set_yticks(range(len(GROUPS)), [g[0].removeprefix("R ") for g in GROUPS])
    ax[0].invert_yaxis()
    ax[0].legend(loc="lower right", fontsize=8)
    ax[1].set_title("td student on MPM dry sand, 1.0 m/s, 8 robots per setting (R = reference)")
    fig.tight_layout()
    fig.savefig(HERE / "fig_convergence.png", dpi=110)


def cost_figure() -> None:
    """Robot-frames per second against robots per solver, with the rate the issue's target needs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [json.loads(line) for line in (HERE / "sweep.jsonl").read_text().splitlines()]
    fig, ax = plt.subplots(figsize=(7, 4))
    series = {}
    for r in rows:
        name = (f"{r['device'].upper()} {100 * r['voxel_m']:.0f} cm / {r['iterations']} it, window "
                f"{r['window_length_m']} x {r['window_width_m']} m, {r['rheology_solver'].replace('auto', 'gs')}")  # fmt: skip
        series.setdefault(name, []).append((r["robots"], r["robot_frames_per_s"]))
    for name, pts in sorted(series.items()):
        x, y = zip(*sorted(pts), strict=True)
        ax.plot(x, y, "o-", label=name)
    need = 100 * 2000 / (60.0 * TARGET_MIN)
    ax.axhline(need, color="k", ls="--", lw=1)
    ax.text(7, need * 1.03, f"needed for 100 ten-second episodes in {TARGET_MIN:.0f} min ({need:.0f})", fontsize=8)
    ax.set_xscale("log", base=2)
    ax.set_xlim(6, 80)
    ax.set_xlabel("robots per MPM solver")
    ax.set_ylabel("robot-frames per second (5 ms frames)")
    ax.set_ylim(0, need * 1.15)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="center left")
    ax.set_title("MPM evaluation cost (td student, dry sand, 30 cm bed)")
    fig.tight_layout()
    fig.savefig(HERE / "fig_cost.png", dpi=110)


TARGET_MIN = 10.0
"""Issue 9's target: 100 ten-second episodes per (policy, terrain) in at most this many minutes on one H200."""


def throughput() -> dict:
    """The issue's throughput verdict at the accepted setting: the best H200 cost case of the 1.4 m window."""
    rows = [json.loads(line) for line in (HERE / "sweep.jsonl").read_text().splitlines()]
    ok = [r for r in rows if r["device"] == "h200" and r["voxel_m"] == 0.03 and r["iterations"] == 500
          and r["window_length_m"] == 1.4 and r["bed_depth_m"] == 0.3]  # fmt: skip
    best = max(ok, key=lambda r: r["robot_frames_per_s"])
    minutes = best["min_per_100_episodes_10s"]
    return {"setting": "3 cm voxels, 500 rheology iterations, 5 ms frames x 1 rigid step, bed 0.3 m, window 1.4 x 0.6 m",
            "device": "NVIDIA H200", "best_case": best["case"], "robots": best["robots"],
            "robot_frames_per_s": best["robot_frames_per_s"], "minutes_per_100_episodes_10s": minutes,
            "target_minutes": TARGET_MIN, "factor_over_target": minutes / TARGET_MIN, "target_met": minutes <= TARGET_MIN,
            "note": "stepping only (2000 frames per episode), without the ~20-40 s build per solver"}  # fmt: skip


def main() -> None:
    """Write report.md, the two figures and throughput.json."""
    lines = [
        "# The accepted-setting runs: convergence check and cost (generated by report.py)",
        "",
        "## Convergence",
        "",
    ]
    lines += [*convergence_table(), "", "## Cost", "", *cost_table()]
    (HERE / "report.md").write_text("\n".join(lines) + "\n")
    figure()
    cost_figure()
    (HERE / "throughput.json").write_text(json.dumps(throughput(), indent=1) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
