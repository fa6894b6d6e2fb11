# SPDX-License-Identifier: Apache-2.0
"""CPU probe (the DP-mapping round): which velocity should the MPM solve see for the box? Three coupling schemes.

The box scene steps the box with the previous frame's sand wrench, then gives the MPM solve a collider velocity
and applies the impulse it returns during the next frame. The velocity given to MPM is:

* ``rewind`` (the scene's scheme): the box's velocity minus the lagged wrench's velocity change, i.e. as if the
  sand had not acted during the frame just stepped;
* ``actual``: the box's velocity as it is;
* ``predict``: the box's velocity plus gravity over the next frame (the velocity the box would reach without sand
  during the frame in which the impulse will be applied).

Study trial ``--trial`` (seed 0), 5 cm voxels, 250 iterations, 0.8 s; ``--case launch`` is the study's forward
launch, ``rest`` the box placed on the surface at rest. Prints the box centre x / z [m] every 8 frames.

    uv run python benchmarks/box_intrusion/coupling_lag_cpu/coupling_scheme_probe.py --scheme predict --case launch
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
import warp as wp
from trial_scene import trial_scene  # this folder: the scripts run as `uv run python <path>`

import gmloco.eval.mpm.kernels_coupling as coupling


def _actual(inv_m: Any, inv_i: Any, dt: float, q: Any, qd: Any, w: Any, out: Any) -> None:
    wp.copy(out, qd)


def _predicted(inv_m: Any, inv_i: Any, dt: float, q: Any, qd: Any, w: Any, out: Any) -> None:
    v = qd.numpy().copy()  # on CPU numpy() is a view of the body state: never write through it
    v[:, 2] -= 9.81 * dt  # linear z of Newton's (linear, angular) body velocity (CPU probe: no graph)
    out.assign(v)


def main() -> None:
    """Swap the scene's velocity hand-over for the chosen scheme, run the trial and print its path."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scheme", choices=["rewind", "actual", "predict"], default="rewind")
    p.add_argument("--case", choices=["launch", "rest"], default="launch")
    p.add_argument("--trial", type=int, default=4)
    args = p.parse_args()
    if args.scheme != "rewind":  # the scene imports the launcher at call time, so patching the module works
        coupling.eval_rewind_body_velocity = _actual if args.scheme == "actual" else _predicted  # type: ignore[assignment]
    _, scene = trial_scene(args.trial, 0.8, at_rest=args.case == "rest")
    scene.run()
    q = np.array([b[0] for b in scene.body_q_all])
    cells = " ".join(f"{scene.frame_dt * (i + 1):.2f}:{q[i, 0]:.3f}/{q[i, 2]:.3f}" for i in range(0, len(q), 8))
    print(args.scheme, args.case, f"trial {args.trial}", cells)


if __name__ == "__main__":
    main()
