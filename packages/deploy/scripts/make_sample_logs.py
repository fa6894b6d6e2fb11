# SPDX-License-Identifier: Apache-2.0
"""Produce the committed sample recordings in ``packages/deploy/data/sample_logs/``.

The G1 in MuJoCo C (mjlab MJCF) on rigid ground, under the *scripted* stepping controller in a virtual gantry
(no trained policy exists yet; every file says ``controller="scripted_stepping"``, ``policy="none"``). Files are
deterministic (no creation time); rerunning overwrites them. Run:
``uv run python packages/deploy/scripts/make_sample_logs.py``.
"""

from __future__ import annotations

from pathlib import Path

from gmloco.deploy.logs.sim import CommandSegment, ScriptedRunCfg, record_scripted_run

OUT = Path(__file__).resolve().parents[1] / "data/sample_logs"

SAMPLES: dict[str, ScriptedRunCfg] = {
    # Speed staircase with ground-truth odometry and contact truth (validates the leg-odometry estimate
    # and the segmentation against the simulator).
    "g1_scripted_rigid_staircase.mcap": ScriptedRunCfg(
        duration=13.0,
        commands=(CommandSegment(0.0, 0.0), CommandSegment(5.0, 0.2), CommandSegment(9.0, 0.4)),
        notes="Speed staircase 0 / 0.2 / 0.4 m/s; ground-truth odometry and contact logged.",
    ),
    # A robot without a base estimator: no /odometry, so gmloco-logs falls back to leg odometry.
    "g1_scripted_rigid_no_odometry.mcap": ScriptedRunCfg(
        duration=7.0,
        commands=(CommandSegment(0.0, 0.3),),
        write_odometry=False,
        write_sim_contact=False,
        notes="Constant 0.3 m/s; no odometry and no contact truth, like a robot without an estimator.",
    ),
}


def main() -> None:
    """Write all samples."""
    OUT.mkdir(parents=True, exist_ok=True)
    for name, cfg in SAMPLES.items():
        path = record_scripted_run(OUT / name, cfg, overwrite=True)
        print(f"{path}: {path.stat().st_size / 1e6:.2f} MB")


if __name__ == "__main__":
    main()
