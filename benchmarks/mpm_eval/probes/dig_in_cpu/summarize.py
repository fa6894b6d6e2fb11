# SPDX-License-Identifier: Apache-2.0
"""Summary table of ``runs.jsonl`` (walking rollouts of ``rft_probe.py`` / ``policy_probe.py``, shallow plates).

Per walking run: pelvis height and the deeper sole's lowest corner / mid-plane depth at 0.25 / 0.5 / 0.75 / 1.0 s,
the largest toe-down sole pitch up to 1 s, the share of logged frames (t <= 1 s) where a foot feels a downward
(negative) vertical sand force and that foot's mean mid-sole depth then, pelvis height and pitch at the run's end,
and the first fall (the evaluation's rule). Prints Markdown.

    uv run python benchmarks/mpm_eval/probes/dig_in_cpu/summarize.py
    uv run python benchmarks/mpm_eval/probes/dig_in_cpu/summarize.py --log results/mpm_eval/probes/velocity_handover_cpu/runs.jsonl <more logs ...>
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


def at(rows: list[dict[str, Any]], t: float) -> dict[str, Any] | None:
    """The logged row nearest to time ``t`` [s] (None if the run ended before)."""
    if rows[-1]["t"] < t - 1e-6:
        return None
    return min(rows, key=lambda r: abs(r["t"] - t))


def walk_row(rec: dict[str, Any]) -> str:
    """One Markdown row of a walking run."""
    rows = rec["rows"]
    if "t" not in rows[0]:
        if "f" not in rows[0]:
            return ""
        # older records (``../material_mapping_gpu/``) log the frame index only
        rows = [{**r, "t": r["f"] * rec.get("frame_dt", 0.01)} for r in rows]
    cells = []
    for t in (0.25, 0.5, 0.75, 1.0):
        r = at(rows, t)
        cells.append("-" if r is None else f"{r['pz']:.2f} / {100 * max(r['low']):.1f} / {100 * max(r['mid']):.1f}")
    early = [r for r in rows if r["t"] <= 1.0 + 1e-6]
    toe = min(min(r["pitch"]) for r in early)
    neg = [(r["fz"][i], r["mid"][i]) for r in early for i in range(2) if r["fz"][i] < -5.0]
    share = len(neg) / (2 * len(early))
    neg_mid = f"{100 * sum(m for _, m in neg) / len(neg):.1f}" if neg else "-"
    cfg = "3D-RFT (training sim)" if rec.get("sim", "").startswith("mujoco") else (
        f"MPM {100 * rec['voxel']:g} cm / {rec['iterations']} its, frame {1000 * rec.get('frame_dt', 0.01):g} ms "
        f"x {rec.get('substeps', 2)}, m_eff {rec.get('effective_mass') or 'm/2'}"
        + (f", {rec['handover']}" if "handover" in rec else "")
    )  # fmt: skip
    fall = rec.get("first_fall_s")
    last = rows[-1]
    end = f"{last['t']:g} s: {last['pz']:.2f} m, {last['pitch_deg']:.0f} deg"
    return (f"| {rec['label']} | {cfg} | " + " | ".join(cells)
            + f" | {toe:.0f} | {100 * share:.0f} % ({neg_mid}) | {end} | {fall if fall is not None else 'no'} |")  # fmt: skip


def main() -> None:
    """Print the tables."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--log", type=Path, nargs="+", default=[Path("results/mpm_eval/probes/dig_in_cpu/runs.jsonl")])
    args = p.parse_args()
    recs = [json.loads(line) for log in args.log for line in log.read_text().splitlines() if line.strip()]
    print(
        "| run | simulator | 0.25 s | 0.5 s | 0.75 s | 1.0 s | toe-down pitch min [deg] | fz < -5 N: frames (mid [cm]) | run end: pelvis, body pitch | fall [s] (50 Hz log) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for rec in recs:
        if rec.get("kind") != "shallow_plate":
            print(walk_row(rec))
    print()
    print("| plate run | voxel / its | " + " | ".join(f"{100 * lo:.1f}-{100 * hi:.1f} cm" for lo, hi in ((0.005, 0.025), (0.025, 0.05), (0.05, 0.075), (0.075, 0.1))) + " |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    for rec in recs:
        if rec.get("kind") == "shallow_plate":
            cells = [
                f"{r['fz_mpm']:.0f} / {r['fz_rft']:.0f} ({r['ratio']:.2f}; min {r['fz_min']:.0f})" for r in rec["rows"]
            ]
            print(
                f"| {rec['label']} | {100 * rec['voxel']:g} cm / {rec['iterations']} {rec['grid']} | "
                + " | ".join(cells)
                + " |"
            )


if __name__ == "__main__":
    main()
