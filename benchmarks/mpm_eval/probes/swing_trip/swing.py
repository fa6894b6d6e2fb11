# SPDX-License-Identifier: Apache-2.0
"""Swing of the G1's feet in MPM sand against the training simulator: table and figure from the probe records.

    uv run python benchmarks/mpm_eval/probes/swing_trip/swing.py

Reads the probe records (``policy_probe.py`` on MPM; ``probes/dig_in_cpu/rft_probe.py`` and ``rft_probe_ts.py`` in MuJoCo +
3D-RFT), prints one markdown row per run with ``policy_probe.swing_summary`` (swings before the fall: apex and
lift of the lowest sole corner and of the sole mid-plane above the initial surface, mean x sand force on swinging
feet), and draws
``swing_trip.png``: the same policy (PPO-3D-RFT, 1.0 m/s, dry sand) in both simulators.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from typing import Any

import numpy as np

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/probes/swing_trip"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""
MPM_EVAL_CODE = Path(__file__).resolve().parents[2]
"""``benchmarks/mpm_eval``: the sibling scripts this one loads."""

HERE = RESULTS_HOME
MPM_EVAL = HERE.parents[1]
RUNS = {  # label -> (record file, simulator)
    "rft3d_train_v1_fx": (MPM_EVAL / "probes/dig_in_cpu/runs.jsonl", "3D-RFT (training sim)"),
    "student_clr50_it1081_rft3d_sole": (HERE / "rft_probe_ts.jsonl", "3D-RFT (training sim)"),
    "student_clr50_it1081_rft3d_box": (HERE / "rft_probe_ts.jsonl", "3D-RFT, whole-box collider"),
    "ppo_rft3d_v3_i250_dt0.005_sub1_3s": (
        MPM_EVAL / "probes/swing_height_gpu/g1_students_v3cm_dt005.jsonl",
        "MPM 3 cm / 5 ms",
    ),
    "student_it2418_v3_i250_dt0.005_sub1": (
        MPM_EVAL / "probes/swing_height_gpu/g1_students_v3cm_dt005.jsonl",
        "MPM 3 cm / 5 ms",
    ),
    "student_clr50_it419_v3_i250_dt0.005_sub1": (
        MPM_EVAL / "probes/swing_height_gpu/g1_students_v3cm_dt005.jsonl",
        "MPM 3 cm / 5 ms",
    ),
    "student_clr50_it1081_v3_i250_dt0.005_sub1": (
        MPM_EVAL / "probes/voxel_size_gpu/g1_student1081_dt005.jsonl",
        "MPM 3 cm / 5 ms",
    ),
    "student_clr50_it1081_v1.5_i250_dt0.005_sub1": (
        MPM_EVAL / "probes/voxel_size_gpu/g1_student1081_dt005.jsonl",
        "MPM 1.5 cm / 5 ms",
    ),
    "student_hs_A_v3_i250_dt0.005_sub1": (HERE / "probe_hs.jsonl", "MPM 3 cm / 5 ms"),
}
FIGURE_PAIR = ("rft3d_train_v1_fx", "ppo_rft3d_v3_i250_dt0.005_sub1_3s")


def load_script(name: str, path: Path) -> Any:
    """Load a results script as a module (they are scripts beside the data, not package modules)."""
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def load(label: str, runs: dict[str, tuple[Path, str]] | None = None) -> dict[str, Any]:
    """The last record of ``label`` in its file (``runs``: label -> (file, name); default this script's ``RUNS``)."""
    path, _ = (RUNS if runs is None else runs)[label]
    recs = [r for r in map(json.loads, path.read_text().splitlines()) if r.get("label") == label]
    if not recs:
        raise SystemExit(f"{path}: no record labelled {label!r}")
    return recs[-1]


def table() -> None:
    """Print the swing table (cm and N)."""
    swing_summary = load_script("policy_probe", MPM_EVAL_CODE / "policy_probe.py").swing_summary
    print("| run | simulator | fall [s] | swings | apex low / mid [cm] | lift low / mid [cm] | x force in swing [N] |")
    print("|---|---|---|---|---|---|---|")
    for label, (_, sim) in RUNS.items():
        rec = load(label)
        fall = rec.get("first_fall_s")
        s = swing_summary(rec["rows"], fall)
        cm = lambda k, s=s: "-" if s.get(k) is None else f"{100 * s[k]:.1f}"  # noqa: E731
        drag = "-" if s.get("swing_drag_x") is None else f"{s['swing_drag_x']:.0f}"
        fall_s = "no" if fall is None else f"{fall:.2f}"
        print(f"| {label} | {sim} | {fall_s} | {s.get('swings', 0)} | {cm('swing_apex_low')} / {cm('swing_apex_mid')} "
              f"| {cm('swing_lift_low')} / {cm('swing_lift_mid')} | {drag} |")  # fmt: skip


def figure(path: Path) -> None:
    """Lowest sole corner height and x sand force per foot up to 1.4 s (before either run falls), swings shaded."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 5.5), sharex=True, sharey="row")
    for col, label in enumerate(FIGURE_PAIR):
        rec, sim = load(label), RUNS[label][1]
        rows = [r for r in rec["rows"] if r["t"] <= 1.4]
        t = np.array([r["t"] for r in rows])
        low, fz, fx = (np.array([r[k] for r in rows]) for k in ("low", "fz", "fx"))
        for foot, color in ((0, "tab:blue"), (1, "tab:orange")):
            swing = fz[:, foot] < 40.0
            axes[0, col].plot(t, -100 * low[:, foot], color=color, label=("left", "right")[foot])
            axes[0, col].fill_between(t, -12, 6, where=swing, color=color, alpha=0.12, step="mid", lw=0)
            axes[1, col].plot(t, np.where(swing, fx[:, foot], np.nan), color=color)
        axes[0, col].axhline(0.0, color="k", lw=0.6)
        axes[1, col].axhline(0.0, color="k", lw=0.6)
        axes[0, col].set_title(f"PPO-3D-RFT, 1.0 m/s, dry sand: {sim}")
        axes[1, col].set_xlabel("time [s]")
    axes[0, 0].set_ylabel("lowest sole corner\nabove initial surface [cm]")
    axes[1, 0].set_ylabel("x sand force on a\nswinging foot [N]")
    axes[0, 0].set_ylim(-12, 6)
    axes[1, 0].set_ylim(-250, 100)
    axes[0, 0].legend(loc="lower left", fontsize=8)
    fig.suptitle("Shaded: swing (sand force < 40 N). In MPM the swinging toe stays in the sand and is dragged back.")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    table()
    figure(HERE / "swing_trip.png")
