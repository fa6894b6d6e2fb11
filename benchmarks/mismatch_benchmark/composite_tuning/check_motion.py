# SPDX-License-Identifier: Apache-2.0
"""What the truth robot does under the composite motion, per command segment (tuning seed).

Per segment: the commanded and the mean measured forward speed and yaw rate (ground-truth odometry, body frame),
the gyro RMS and the mean base height, on a null episode, from 1 s after the segment starts.

Usage: ``uv run python benchmarks/mismatch_benchmark/composite_tuning/check_motion.py --seed 550``
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
from gmloco.deploy.mismatch.benchmark.policy_motion import MOTIONS, motion_cfg


def main() -> None:
    """Generate the recording and print one JSON line per segment."""
    p = argparse.ArgumentParser()
    p.add_argument("--seed", type=int, default=550)
    a = p.parse_args()
    cfg = motion_cfg("composite")
    rec, _ = generate(EpisodeCfg(duration=MOTIONS["composite"], seed=a.seed, odometry=True, ground="sand", policy=cfg))
    assert cfg.schedule is not None and rec.base_linvel is not None and rec.base_angvel is not None
    ends = [s[0] for s in cfg.schedule[1:]] + [float(rec.t[-1]) + rec.dt]
    for seg, end in zip(cfg.schedule, ends, strict=True):
        # skip the first second of each segment (the policy's response)
        m = (rec.t >= seg[0] + 1.0) & (rec.t < end)
        print(
            json.dumps(
                {
                    "t_s": [seg[0], end],
                    "cmd_vx": seg[1],
                    "cmd_wz": seg[3],
                    "vx_mean": float(np.mean(rec.base_linvel[m, 0])),
                    "wz_mean": float(np.mean(rec.base_angvel[m, 2])),
                    "gyro_rms": float(np.sqrt(np.mean(rec.imu_gyro[m] ** 2))),
                    "base_z_mean": float(np.mean(rec.base_pos[m, 2])) if rec.base_pos is not None else None,
                }
            ),
            flush=True,
        )


if __name__ == "__main__":
    main()
