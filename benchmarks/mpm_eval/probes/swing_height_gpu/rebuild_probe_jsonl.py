# SPDX-License-Identifier: Apache-2.0
"""Rebuild the probe records of the swing-height probes from the probes' stdout (their ``--log`` path was lost on the machine).

``policy_probe.py`` prints every logged row and the run's summary dict; this reads them back into the record shape
that ``--log`` would have held (``particles`` and ``mass`` were not printed: None). Run from the repository root:

    uv run python benchmarks/mpm_eval/probes/swing_height_gpu/rebuild_probe_jsonl.py
"""

from __future__ import annotations

import ast
import json
from pathlib import Path

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/probes/swing_height_gpu"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
SETTINGS = dict(vx_cmd=1.0, window="eval", rigid=False, depth=0.3, voxel=0.03, iterations=250, frames=600,
                frame_dt=0.005, substeps=1, effective_mass=None, grid="sparse", handover="predict")  # fmt: skip
POLICIES = {
    "old": "artifacts/gm_loco_student/policy.onnx",
    "new": "artifacts/gm_loco_student_clr50 (it 419, CPU export of the swing-height probes machine-1 checkpoint)",
    "ppo": "artifacts/ppo_rft3d/policy.onnx",
}


def rebuild(log: Path, policy: str) -> dict:
    """Return the record of one probe log."""
    rows, summary, label = [], None, None
    for line in log.read_text().splitlines():
        head, _, rest = line.partition(" {")
        if not rest or " " in head:
            continue
        value = ast.literal_eval("{" + rest)
        label = head
        if "t" in value:
            rows.append(value)
        else:
            summary = value
    if summary is None:
        raise ValueError(f"{log}: no summary line (the probe did not finish)")
    return dict(label=label, policy=policy, **SETTINGS, mass=None, particles=None, rows=rows, **summary)


def main() -> None:
    """Write ``g1_students_v3cm_dt005.jsonl`` next to this file."""
    out = HERE / "g1_students_v3cm_dt005.jsonl"
    recs = [rebuild(HERE / f"{k}.log", v) for k, v in POLICIES.items()]
    out.write_text("".join(json.dumps(r) + "\n" for r in recs))
    print(f"{out}: {len(recs)} records")


if __name__ == "__main__":
    main()
