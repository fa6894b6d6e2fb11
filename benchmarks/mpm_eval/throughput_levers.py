# SPDX-License-Identifier: Apache-2.0
"""Every throughput lever measured for issue 9, against the 10-minute target -> ``throughput_levers.{json,png}``.

Reads the studies' committed measurements (robot-frames/s of the MPM evaluation: MPM frames per second x robots
stepping in one solver) and marks each case by the convergence check's verdict on its physics: ``accepted`` (the
setting the tables use, or a change that leaves the physics alone: grid reserve, lanes, solver variant) or
``rejected`` (a cheaper setting whose walks differ). The target: 100 ten-second walking episodes (5 ms frames) in
10 minutes = 333 robot-frames/s. A row split over several GPUs (the ablation-circle runs) is drawn as the rate its wall-clock
stands for (100 x 10 s / wall-clock), apart from the one-GPU cases.

    python benchmarks/mpm_eval/throughput_levers.py
"""

from __future__ import annotations

import json
import statistics
from pathlib import Path

MPM_RESULTS = Path(__file__).resolve().parents[2] / "results" / "mpm_eval"  # the runs read, the outputs written
TARGET_RF_S = 100 * 10.0 / 0.005 / 600.0


def _load(rel: str) -> dict:
    return json.loads((MPM_RESULTS / rel).read_text())


def cases() -> list[dict]:
    """(label, GPU, robot-frames/s, verdict, source) of every measured case, oldest study first."""
    out = []

    def add(label: str, gpu: str, rf: float, verdict: str, source: str, gpus: int = 1) -> None:
        out.append({"label": label, "gpu": gpu, "gpus": gpus, "robot_frames_per_s": round(rf, 1), "verdict": verdict,
                    "x_target": round(rf / TARGET_RF_S, 3), "source": source})  # fmt: skip

    s12 = {
        json.loads(line)["case"]: json.loads(line)
        for line in (MPM_RESULTS / "convergence/accepted_setting/sweep.jsonl").read_text().splitlines()
    }
    add("s12: 5 cm / 1000 sweeps, 1.8 x 0.6 m, 32 lanes", "H100", s12["td_v0.05_it1000_r32"]["robot_frames_per_s"], "rejected",
        "convergence/accepted_setting/sweep.jsonl")  # fmt: skip
    s12best = _load("convergence/accepted_setting/throughput.json")
    add("s12: accepted setting, grid reserve 3.0x, 64 lanes", "H200", s12best["robot_frames_per_s"], "accepted",
        "convergence/accepted_setting/throughput.json")  # fmt: skip
    for c in _load("convergence/grid_capacity_solvers/throughput.json")["cases"]:
        add(
            f"s13: {c['label']}",
            "H200",
            c["robot_frames_per_s"],
            "accepted",
            "convergence/grid_capacity_solvers/throughput.json",
        )
    cost = _load("window_study/window_behind_pelvis/cost.json")["cases"]
    for key, verdict in (("cost/r32_l1.4_w0.6_d0.3", "accepted"), ("cost/r32_l1.0_w0.5_d0.3", "rejected"),
                         ("cost/r32_l0.8_w0.5_d0.25", "rejected"), ("cost/r64_l0.8_w0.5_d0.25", "rejected")):  # fmt: skip
        add(
            f"s15: {cost[key]['label']}",
            "H100",
            cost[key]["robot_frames_per_s"],
            verdict,
            "window_study/window_behind_pelvis/cost.json",
        )
    for name, c in _load("table_rows/per_terrain/throughput.json")["rows"].items():
        if name in ("table_td_poppy_seed", "table_td_dry_sand_deep", "table_clr50_dry_sand_l1.4"):
            add(f"s16: row {name.removeprefix('table_')}, 50 lanes (shared host)", "H100",
                c["robot_frames_per_s_all_lanes"], "accepted", "table_rows/per_terrain/throughput.json")  # fmt: skip
    for c in sorted(
        _load("table_rows/rough_circles_lanes/throughput.json")["lanes_case"].values(), key=lambda v: v["lanes"]
    ):
        add(f"s17: {c['lanes']} lanes, 0.3 s (side by side)", "H100", c["robot_frames_per_s_all_lanes"], "accepted",
            "table_rows/rough_circles_lanes/throughput.json")  # fmt: skip
    s18 = _load("table_rows/ablation_circles/throughput.json")
    shares = [s18["runs"][f"table_td_dry_sand_x4_share{i}of4"]["robot_frames_per_s_all_lanes"] for i in range(4)]
    add("s18: td dry-sand row, 25 lanes per GPU (median of 4 shares)", "H200", statistics.median(shares), "accepted",
        "table_rows/ablation_circles/throughput.json")  # fmt: skip
    row = s18["rows"]["table_td_dry_sand_x4"]
    add(f"s18: the same row on 4 GPUs at once: {row['wall_minutes']} min incl. build (as a rate)", "4x H200",
        100 * 10.0 / 0.005 / (row["wall_minutes"] * 60), "accepted", "table_rows/ablation_circles/throughput.json", gpus=4)  # fmt: skip

    def retire_ab(label: str, folder: str, seconds: int, runs: tuple[str, str]) -> None:
        """A side-by-side retire-lanes A/B (kept run, retired run) of the row folder ``folder``: two cases."""
        data = _load(f"{folder}/throughput.json")
        for run, how in zip(runs, ("idle lanes kept", "idle lanes retired"), strict=True):
            add(f"{label}: 25 lanes, {seconds} s at 1.5 m/s, {how} (side by side)", "H200",
                data["runs"][run]["robot_frames_per_s_all_lanes"], "accepted", f"{folder}/throughput.json")  # fmt: skip

    retire_ab("s19", "table_rows/transition_course", 6, ("retire_ab_keep", "retire_ab_on"))
    s19 = _load("table_rows/transition_course/throughput.json")
    row = s19["rows"]["table_td_transition_sq"]
    add(f"s19: transition row, square 1.4 x 1.4 m window, 4 GPUs: {row['wall_minutes']} min (as a rate)", "4x H200",
        100 * 10.0 / 0.005 / (row["wall_minutes"] * 60), "accepted", "table_rows/transition_course/throughput.json", gpus=4)  # fmt: skip
    s20 = _load("table_rows/dry_sand_square_window/throughput.json")
    shares = [s20["runs"][f"table_td_dry_sand_sq_share{i}of4"]["robot_frames_per_s_all_lanes"] for i in (0, 1, 3)]
    add("s20: td dry-sand row, square 1.4 x 1.4 m window, 25 lanes (median of 3 shares)", "H200",
        statistics.median(shares), "accepted", "table_rows/dry_sand_square_window/throughput.json")  # fmt: skip
    s21 = _load("table_rows/poppy_seed_deep_sand_reach/throughput.json")
    shares = [s21["runs"][f"table_td_poppy_seed_reach_share{i}of4"]["robot_frames_per_s_all_lanes"] for i in range(4)]
    add("s21: td poppy-seed row, reach 1.7 x 0.8 m window, 25 lanes (median of 4 shares)", "H200",
        statistics.median(shares), "accepted", "table_rows/poppy_seed_deep_sand_reach/throughput.json")  # fmt: skip
    # its rows (8.1 / 5.7 min on 2 GPUs) are not rates of 10 s walks: their robots fall within ~1-2 s
    s22 = _load("table_rows/basalt_rough_square_window/throughput.json")
    shares = [s22["runs"][f"table_td_basalt_sq_share{i}of4"]["robot_frames_per_s_all_lanes"] for i in range(4)]
    add("s22: td basalt row, square 1.4 x 1.4 m window, 25 lanes (median of 4 shares)", "H200",
        statistics.median(shares), "accepted", "table_rows/basalt_rough_square_window/throughput.json")  # fmt: skip
    row = s22["rows"]["table_td_basalt_sq"]  # every robot walks the 10 s: a clean walking row
    add(f"s22: basalt row, square window, 4 GPUs: {row['wall_minutes']} min incl. build (as a rate)", "4x H200",
        100 * 10.0 / 0.005 / (row["wall_minutes"] * 60), "accepted", "table_rows/basalt_rough_square_window/throughput.json", gpus=4)  # fmt: skip
    retire_ab("s23", "table_rows/last_rows_retire_lanes", 10, ("retire_ab10_keep", "retire_ab10_on"))
    return out


def main() -> None:
    """Write ``throughput_levers.json`` and ``fig_throughput_levers.png`` beside this script."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = cases()
    one_gpu = [r for r in rows if r["verdict"] == "accepted" and r["gpus"] == 1]
    best = max(one_gpu, key=lambda r: r["robot_frames_per_s"])
    doc = {"target_robot_frames_per_s": round(TARGET_RF_S, 1), "best_accepted": best,
           "target_over_best_accepted": round(TARGET_RF_S / best["robot_frames_per_s"], 2), "cases": rows}  # fmt: skip
    (MPM_RESULTS / "throughput_levers.json").write_text(json.dumps(doc, indent=1) + "\n")
    fig, ax = plt.subplots(figsize=(9, 0.32 * len(rows) + 1.4), constrained_layout=True)
    y = range(len(rows))
    colors = ["C2" if r["gpus"] > 1 else "C0" if r["verdict"] == "accepted" else "0.7" for r in rows]
    ax.barh(list(y), [r["robot_frames_per_s"] for r in rows], color=colors)
    for k, r in enumerate(rows):
        ax.text(r["robot_frames_per_s"] + 3, k, f"{r['robot_frames_per_s']:.0f} ({r['gpu']})", va="center", fontsize=7)
    ax.set_yticks(list(y), [r["label"] for r in rows], fontsize=7)
    ax.invert_yaxis()
    ax.axvline(TARGET_RF_S, color="C3", ls="--", label=f"target: 100 x 10 s in 10 min ({TARGET_RF_S:.0f})")
    ax.bar(0, 0, color="C0", label="accepted by the convergence check")
    ax.bar(0, 0, color="0.7", label="rejected (the walk changes)")
    ax.bar(0, 0, color="C2", label="one row split over several GPUs: 100 x 10 s / its wall-clock")
    ax.set_xlabel("robot-frames/s per GPU\n(3 cm, 500 sweeps, 5 ms frames, 30 cm bed, 1.4 x 0.6 m unless named)")
    ax.set_xlim(0, TARGET_RF_S * 1.2)
    ax.legend(fontsize=7, loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=2)
    fig.savefig(MPM_RESULTS / "fig_throughput_levers.png", dpi=130)
    print(
        f"best accepted on one GPU: {best['label']} {best['robot_frames_per_s']} ({best['gpu']}); "
        f"the target is {doc['target_over_best_accepted']}x that"
    )


if __name__ == "__main__":
    main()
