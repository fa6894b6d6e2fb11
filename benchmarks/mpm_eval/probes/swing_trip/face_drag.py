# SPDX-License-Identifier: Apache-2.0
"""What a buried swinging foot meets in 3D-RFT: the training collider (sole face only) against all six box faces.

    uv run python benchmarks/mpm_eval/probes/swing_trip/face_drag.py

The float64 reference 3D-RFT (``gmloco.contact.reference.rft3d``, PNAS coefficients, dry sand) on the G1 foot box
(``gmloco.contact.colliders``, 5 x 5 points per face), pitched toe down and sunk until its lowest point is at a
given depth, moving forward and up as a swinging foot does. Prints the force of the sand on the foot [N] for the
training collider (``faces="sole"``) and for the whole box (``faces="box"``).
"""

from __future__ import annotations

import math

import numpy as np

from gmloco.contact import MATERIAL_PRESETS
from gmloco.contact.colliders import g1_foot_collider
from gmloco.contact.reference.rft3d import rft3d_forces


def foot_force(faces: str, depth: float, toe_down_deg: float, velocity: tuple[float, float, float]) -> np.ndarray:
    """Sand force on the foot [N], [3]: box pitched ``toe_down_deg``, lowest point ``depth`` [m] below z = 0."""
    col = g1_foot_collider(faces)  # type: ignore[arg-type]
    a = math.radians(toe_down_deg)
    rot = np.array([[math.cos(a), 0.0, math.sin(a)], [0.0, 1.0, 0.0], [-math.sin(a), 0.0, math.cos(a)]])  # +x down
    pts, nrm = col.points @ rot.T, col.normals @ rot.T
    box = g1_foot_collider("box")
    lowest = float((box.points @ rot.T)[:, 2].min())  # the same box placement for both colliders
    pts = pts - np.array([0.0, 0.0, lowest + depth])
    mat = MATERIAL_PRESETS["dry_sand"]
    vel = np.tile(np.asarray(velocity, dtype=np.float64), (len(pts), 1))
    f = rft3d_forces(pts, nrm, vel, col.areas, rho_c=mat.rho_c, mu_int=mat.mu_int, mu_surf=mat.mu_surf)
    return f.sum(axis=0)


def main() -> None:
    """Print the table."""
    print("dry sand, PNAS 3D-RFT; force of the sand on the foot")
    print(
        "| velocity [m/s] | lowest point depth [cm] | toe down [deg] | sole only: Fx / Fz [N] | whole box: Fx / Fz [N] |"
    )
    print("|---|---|---|---|---|")
    for v in ((1.5, 0.0, 0.2), (1.5, 0.0, 0.0)):
        for toe in (0.0, 15.0):
            for depth in (0.02, 0.04, 0.06, 0.08):
                s, b = foot_force("sole", depth, toe, v), foot_force("box", depth, toe, v)
                print(f"| {v} | {100 * depth:.0f} | {toe:.0f} | {s[0]:.1f} / {s[2]:.1f} | {b[0]:.1f} / {b[2]:.1f} |")


if __name__ == "__main__":
    main()
