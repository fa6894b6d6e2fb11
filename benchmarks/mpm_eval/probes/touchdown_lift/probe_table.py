# SPDX-License-Identifier: Apache-2.0
"""The touchdown-lift students on MPM sand against the delivered student: table and figure from the probe records.

    uv run python benchmarks/mpm_eval/probes/touchdown_lift/probe_table.py

Reads the ``policy_probe.py`` records of the touchdown-lift study (``probe_td.jsonl``: the new student after 282 iterations
(chunk A) and after 672 (chunk B), 3 s and 10 s walks at 1.0 and 1.5 m/s) and the delivered student's record of
the voxel-size probes (same numerics: 3 cm voxels, 250 iterations, 5 ms frames x 1 step, 30 cm of dry sand), and the
resolution check run on the CPU (``probe_td_cpu.jsonl``: the it-672 walk at 5 cm with 250 / 100 / 50 iterations and
5 or 10 ms frames). Prints one
markdown row per walk (fall time, mean forward speed, the stance depth of the soles, and
``policy_probe.swing_summary``'s swing apex / lift / drag before the fall) and draws ``fig_probe_td.png``: pelvis
height, forward speed and the left sole's lowest corner over time.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/probes/touchdown_lift"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""
MPM_EVAL_CODE = Path(__file__).resolve().parents[2]
"""``benchmarks/mpm_eval``: the sibling scripts this one loads."""

HERE = RESULTS_HOME
MPM_EVAL = HERE.parents[1]
RUNS = {  # label -> (record file, short name)
    "student_clr50_it1081_v3_i250_dt0.005_sub1": (
        MPM_EVAL / "probes/voxel_size_gpu/g1_student1081_dt005.jsonl",
        "delivered student (clr50, it 1,081)",
    ),
    "student_td_A_v3_i250_dt0.005_sub1": (HERE / "probe_td.jsonl", "td student, it 282 (chunk A)"),
    "student_td_A_v3_i250_dt0.005_sub1_10s": (HERE / "probe_td.jsonl", "td student, it 282 (chunk A)"),
    "student_td_A_v3_i250_dt0.005_sub1_10s_vx1.5": (HERE / "probe_td.jsonl", "td student, it 282 (chunk A)"),
    "student_td_B_v3_i250_dt0.005_sub1_10s": (HERE / "probe_td.jsonl", "td student, it 672 (chunk B)"),
    "student_td_B_v3_i250_dt0.005_sub1_10s_vx1.5": (HERE / "probe_td.jsonl", "td student, it 672 (chunk B)"),
    # resolution check, on the CPU (2 cores) with Warp's CPU device: the same walk at coarser numerics
    "student_td_B_v5_i250_dt0.005_sub1_10s_cpu": (HERE / "probe_td_cpu.jsonl", "td student, it 672, CPU"),
    "student_td_B_v5_i100_dt0.005_sub1_10s_cpu": (HERE / "probe_td_cpu.jsonl", "td student, it 672, CPU"),
    "student_td_B_v5_i50_dt0.005_sub1_10s_cpu": (HERE / "probe_td_cpu.jsonl", "td student, it 672, CPU"),
    "student_td_B_v5_i50_dt0.01_sub2_10s_cpu": (HERE / "probe_td_cpu.jsonl", "td student, it 672, CPU"),
}
FIGURE_RUNS = (
    "student_clr50_it1081_v3_i250_dt0.005_sub1",
    "student_td_A_v3_i250_dt0.005_sub1_10s",
    "student_td_B_v3_i250_dt0.005_sub1_10s",
    "student_td_B_v3_i250_dt0.005_sub1_10s_vx1.5",
)
STANCE_N = 150.0
"""A sole carrying more than this sand force [N] counts as in stance for the stance-depth column."""


def _swing_module() -> Any:
    """``probes/swing_trip/swing.py``: its script loader (and through it ``policy_probe.swing_summary``) and record reader."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("swing_s9", MPM_EVAL_CODE / "probes/swing_trip/swing.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


SWING = _swing_module()


def load(label: str) -> dict[str, Any]:
    """The last record of ``label`` in its file."""
    return SWING.load(label, RUNS)


def stance_depth(rows: list[dict[str, Any]], fall: float | None) -> float | None:
    """Median depth [m] of the loaded soles' lowest corner below the initial surface, before the fall."""
    depths = [r["low"][k] for r in rows if fall is None or r["t"] < fall for k in (0, 1) if r["fz"][k] > STANCE_N]
    return float(np.median(depths)) if depths else None


def table() -> None:
    """Print the table (cm, m/s, N)."""
    swing_summary = SWING.load_script("policy_probe", MPM_EVAL_CODE / "policy_probe.py").swing_summary
    print(
        "| policy | voxel / iterations / frame | command [m/s] | walk [s] | fall [s] | mean speed before a fall [m/s] | max tilt [deg] | stance depth [cm] "
        "| swings | swing apex low / mid [cm] | lift low / mid [cm] | x force in swing [N] |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for label, (_, name) in RUNS.items():
        rec = load(label)
        fall = rec.get("first_fall_s")
        s = swing_summary(rec["rows"], fall)
        cm = lambda v: "-" if v is None else f"{100 * v:.1f}"  # noqa: E731
        depth = stance_depth(rec["rows"], fall)
        drag = "-" if s.get("swing_drag_x") is None else f"{s['swing_drag_x']:.0f}"
        walk = rec["frames"] * rec["frame_dt"]
        tilt = f"{rec['max_tilt_deg']:.0f}" if fall is None else "-"
        speed = np.mean([r["vx"] for r in rec["rows"] if fall is None or r["t"] < fall])
        print(
            f"| {name} | {100 * rec['voxel']:.0f} cm / {rec['iterations']} / {1000 * rec['frame_dt']:.0f} ms "
            f"| {rec['vx_cmd']:.1f} | {walk:.0f} | {'no' if fall is None else f'{fall:.2f}'} "
            f"| {speed:.2f} | {tilt} | {cm(depth)} | {s.get('swings', 0)} "
            f"| {cm(s.get('swing_apex_low'))} / {cm(s.get('swing_apex_mid'))} "
            f"| {cm(s.get('swing_lift_low'))} / {cm(s.get('swing_lift_mid'))} | {drag} |"
        )


RESOLUTION_RUNS = (
    "student_td_B_v3_i250_dt0.005_sub1_10s",
    "student_td_B_v5_i250_dt0.005_sub1_10s_cpu",
    "student_td_B_v5_i100_dt0.005_sub1_10s_cpu",
    "student_td_B_v5_i50_dt0.005_sub1_10s_cpu",
    "student_td_B_v5_i50_dt0.01_sub2_10s_cpu",
)


def figure(path: Path, runs: tuple[str, ...] = FIGURE_RUNS, title: str = "", numerics: bool = False) -> None:
    """Pelvis height, forward speed and the left sole's lowest corner over time, one line per walk."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    for label in runs:
        rec = load(label)
        rows = rec["rows"]
        fall = rec.get("first_fall_s")
        end = fall + 0.3 if fall is not None else rows[-1]["t"]
        rows = [r for r in rows if r["t"] <= end]
        t = np.array([r["t"] for r in rows])
        what = (
            f"{100 * rec['voxel']:.0f} cm, {rec['iterations']} its, {1000 * rec['frame_dt']:.0f} ms"
            if numerics
            else f"{RUNS[label][1]}, {rec['vx_cmd']:.1f} m/s"
        )
        tag = what + (f" (falls {fall:.1f} s)" if fall else " (no fall)")
        (line,) = axes[0].plot(t, [r["pz"] for r in rows], label=tag, lw=1.2)
        axes[1].plot(t, [r["vx"] for r in rows], color=line.get_color(), lw=0.8)
        axes[2].plot(t, [-100 * r["low"][0] for r in rows], color=line.get_color(), lw=0.8)
    axes[0].axhline(0.2, color="k", lw=0.6, ls="--")
    axes[0].set_ylabel("pelvis height [m]")
    axes[0].set_ylim(0.0, 0.85)
    axes[0].legend(fontsize=8, loc="lower left")
    axes[1].set_ylabel("forward speed [m/s]")
    axes[1].set_ylim(-0.5, 2.5)
    axes[2].axhline(0.0, color="k", lw=0.6)
    axes[2].set_ylabel("left sole, lowest corner\nabove initial surface [cm]")
    axes[2].set_ylim(-25, 20)
    axes[2].set_xlabel("time [s]")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    table()
    figure(
        HERE / "fig_probe_td.png",
        title="G1 students on MPM dry sand (3 cm voxels, 200 Hz coupling): delivered vs touchdown-lift student",
    )
    figure(
        HERE / "fig_resolution.png",
        RESOLUTION_RUNS,
        "The it-672 student at 1.0 m/s on MPM dry sand: resolution check (3 cm on the GPU, 5 cm on the CPU)",
        numerics=True,
    )
