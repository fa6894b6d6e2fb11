# SPDX-License-Identifier: Apache-2.0
"""How far from the pelvis do the soles reach while in the sand? The window sizes against the recorded walks.

For each recording (the first episode of every speed that a table row kept, ``recordings/*.mcap``), the soles'
corners are placed by forward kinematics (MuJoCo, mjlab's G1 MJCF, the sole boxes of ``SoleCfg``) from the
logged base pose and joint angles, and expressed in the pelvis' yaw frame (x forward). Only frames where a corner
is below ``--near`` above the sand surface (z = 0) count: those are the ones that need sand under them. Prints,
per recording, the reach behind / ahead of the pelvis and sideways, the share of those corners outside each window
and the first time one was (compare with the recording's length: a fall ends it), and writes ``foot_reach.json``
and ``fig_foot_reach.png`` with the edges of the windows. (Since the voxel-reference runs every ``g1_eval`` episode records the
same check against its own window, ``window_exit_s``; this script covers the runs recorded before.)

    uv run python benchmarks/mpm_eval/convergence/voxel_reference_foot_reach/foot_reach.py --runs results/mpm_eval/convergence/grid_capacity_solvers/runs/table_td_dry_sand
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/convergence/voxel_reference_foot_reach"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

WINDOWS = {  # name: (length, width, lead) [m]; x spans lead -/+ length / 2 around the pelvis, y +-width / 2
    "1.4 x 0.6, lead 0.2 (default)": (1.4, 0.6, 0.2),
    "1.0 x 0.5, lead 0.1": (1.0, 0.5, 0.1),
    "0.8 x 0.4, lead 0.1": (0.8, 0.4, 0.1),
    "1.0 x 0.5, lead -0.1": (1.0, 0.5, -0.1),
    "0.8 x 0.5, lead -0.1": (0.8, 0.5, -0.1),
}


def reach(path: Path, near: float) -> dict:
    """Reach of the soles relative to the pelvis (yaw frame) over the frames a corner is near or in the sand."""
    import mujoco

    from gmloco.deploy.logs.reader import read_log
    from gmloco.eval.g1.soles import SoleCfg, g1_mjcf_path, sole_box_corners
    from gmloco.eval.metrics.locomotion import quat_wxyz_to_roll_pitch_yaw

    log = read_log(path)
    t_q, q = log.signal("lowstate.q")
    t_o, pos = log.signal("odom.position")
    _, quat = log.signal("odom.orientation")
    model = mujoco.MjModel.from_xml_path(str(g1_mjcf_path()))
    data = mujoco.MjData(model)
    addr = [model.jnt_qposadr[model.joint(name).id] for name in log.joint_names]
    feet = [model.body(f"{side}_ankle_roll_link").id for side in ("left", "right")]
    local = sole_box_corners(SoleCfg())
    rel, first_exit = [], {}
    for k, t in enumerate(t_q):
        i = min(int(np.searchsorted(t_o, t)), len(t_o) - 1)
        data.qpos[:3], data.qpos[3:7] = pos[i], quat[i]
        data.qpos[addr] = q[k]
        mujoco.mj_kinematics(model, data)
        corners = np.concatenate([data.xpos[b] + local @ data.xmat[b].reshape(3, 3).T for b in feet])
        if corners[:, 2].min() > near:
            continue
        yaw = quat_wxyz_to_roll_pitch_yaw(quat[i])[2]
        c, s = np.cos(yaw), np.sin(yaw)
        d = corners[corners[:, 2] <= near][:, :2] - pos[i][:2]
        rel.append(np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1))
        for name, w in WINDOWS.items():
            if name not in first_exit and _outside(rel[-1], *w).any():
                first_exit[name] = round(float(t - t_q[0]), 2)
    pts = np.concatenate(rel) if rel else np.zeros((0, 2))
    if not len(pts):
        return {"recording": str(path), "frames": 0}
    return {
        "recording": str(path), "frames": len(rel), "duration_s": float(t_q[-1] - t_q[0]),
        "behind_m": float(-pts[:, 0].min()), "ahead_m": float(pts[:, 0].max()),
        "behind_p1_m": float(-np.percentile(pts[:, 0], 1)), "ahead_p99_m": float(np.percentile(pts[:, 0], 99)),
        "side_m": float(np.abs(pts[:, 1]).max()),
        "outside": {name: float(np.mean(_outside(pts, *w))) for name, w in WINDOWS.items()},
        "first_exit_s": {name: first_exit.get(name) for name in WINDOWS},
        "points": pts[:: max(1, len(pts) // 4000)].round(4).tolist(),
    }  # fmt: skip


def _outside(pts: np.ndarray, length: float, width: float, lead: float) -> np.ndarray:
    """Which points lie outside a window (x in lead -/+ length / 2, |y| <= width / 2)."""
    return (pts[:, 0] < lead - length / 2) | (pts[:, 0] > lead + length / 2) | (np.abs(pts[:, 1]) > width / 2)


def figure(rows: list[dict], path: Path) -> None:
    """The sole points of each recording in the pelvis' yaw frame, with the windows' outlines; a row per run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in rows if r["frames"]]
    runs = list(dict.fromkeys(Path(r["recording"]).parents[1].name for r in rows))
    cols = max(sum(Path(r["recording"]).parents[1].name == run for r in rows) for run in runs)
    fig, axes = plt.subplots(len(runs), cols, figsize=(3.0 * cols, 1.9 * len(runs) + 0.6), sharex=True, sharey=True,
                             constrained_layout=True, squeeze=False)  # fmt: skip
    for i, run in enumerate(runs):
        for j, r in enumerate(r for r in rows if Path(r["recording"]).parents[1].name == run):
            ax, p = axes[i, j], np.array(r["points"])
            ax.plot(p[:, 0], p[:, 1], ".", ms=1, alpha=0.3, color="k")
            for (name, (length, width, lead)), color in zip(
                WINDOWS.items(), ("C0", "C1", "C3", "C2", "C4"), strict=True
            ):
                x0 = lead - length / 2
                ax.add_patch(plt.Rectangle((x0, -width / 2), length, width, fill=False, ec=color, lw=0.8, label=name))
            speed = Path(r["recording"]).stem.split("__v")[-1]
            ax.set_title(f"{run.removeprefix('table_')}, {speed} m/s ({r['duration_s']:.1f} s)", fontsize=7)
            ax.set(xlim=(-0.85, 0.95), ylim=(-0.45, 0.45), aspect="equal")
        axes[i, 0].set_ylabel("y [m]")
    for ax in axes[-1]:
        ax.set_xlabel("x ahead of the pelvis [m]")
    axes[0, 0].legend(fontsize=5, loc="lower left")
    fig.suptitle("sole corners within 2 cm of the sand surface (pelvis yaw frame) against the sand windows", fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    """Command line."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", nargs="+", type=Path, required=True, help="g1_eval run folders with recordings/")
    p.add_argument("--near", type=float, default=0.02, help="a corner counts below this height above z = 0 [m]")
    p.add_argument("--out", type=Path, default=RESULTS_HOME)
    a = p.parse_args()
    rows = []
    for run in a.runs:
        for rec in sorted((run / "recordings").glob("*.mcap"), key=lambda f: float(f.stem.split("__v")[-1])):
            r = reach(rec, a.near)
            rows.append(r)
            if r["frames"]:
                print(f"{rec}: {r['frames']} frames over {r['duration_s']:.1f} s; behind {r['behind_m']:.2f} m "
                      f"(1 %: {r['behind_p1_m']:.2f}), ahead {r['ahead_m']:.2f} m (99 %: {r['ahead_p99_m']:.2f}), "
                      f"side {r['side_m']:.2f} m; outside (first exit [s]): "
                      + ", ".join(f"{k} {100 * v:.1f} % ({r['first_exit_s'][k]})" for k, v in r["outside"].items()))  # fmt: skip
    (a.out / "foot_reach.json").write_text(
        json.dumps([{k: v for k, v in r.items() if k != "points"} for r in rows], indent=1) + "\n"
    )
    figure(rows, a.out / "fig_foot_reach.png")


if __name__ == "__main__":
    main()
