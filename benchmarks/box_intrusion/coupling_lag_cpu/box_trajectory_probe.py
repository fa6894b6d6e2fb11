# SPDX-License-Identifier: Apache-2.0
"""CPU probe (the DP-mapping round): the path of one MPM box-study trial (forward launch), every third frame.

The study's trial ``--trial`` medium (seed 0), 5 cm voxels, 250 iterations, study defaults otherwise, 1 s. Prints
time [s], box centre x and z [m] (resting height on the undisturbed surface 0.1 m) and pitch [deg].

    uv run python benchmarks/box_intrusion/coupling_lag_cpu/box_trajectory_probe.py --trial 4
"""

from __future__ import annotations

import argparse

import numpy as np
from trial_scene import trial_scene  # this folder: the scripts run as `uv run python <path>`


def main() -> None:
    """Run the trial and print its path."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--trial", type=int, default=4)
    p.add_argument("--duration", type=float, default=1.0)
    args = p.parse_args()
    _, scene = trial_scene(args.trial, args.duration)
    scene.run()
    q = np.array([b[0] for b in scene.body_q_all])
    x, y, z, w = q[:, 3], q[:, 4], q[:, 5], q[:, 6]
    pitch = np.degrees(np.arccos(np.clip(1 - 2 * (x * x + y * y), -1, 1))) * np.sign(2 * (x * z + w * y))
    for i in range(0, len(q), 3):
        print(f"t={scene.frame_dt * (i + 1):.2f} x={q[i, 0]:.3f} z={q[i, 2]:.3f} pitch={pitch[i]:6.1f}")


if __name__ == "__main__":
    main()
