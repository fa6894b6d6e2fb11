# SPDX-License-Identifier: Apache-2.0
"""The float64 3D-RFT reference (with ``RftExtensionsCfg``) as a sole-experiment sand, and its replay of a record.

The sand's wrench sums the reference's element forces f_i [N] and their torques r_i x f_i about the sole-box centre,
r_i [m] the element's lever arm from the centre in world axes.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from gmloco.contact import ColliderBoxCfg, ColliderPoints, ContactRFT3DCfg, MaterialCfg, box_collider
from gmloco.contact.reference.rft3d_extensions import ExtState, advance_ext_state, rft3d_extended_forces
from gmloco.eval.calibration.protocol import SoleProtocolCfg, SoleRecord, SoleSand

__all__ = ["centred_sole_collider", "replay_wrench", "rft_sole_sand"]


def centred_sole_collider(protocol: SoleProtocolCfg, faces: str = "box", resolution: int = 5) -> ColliderPoints:
    """Return the sole box sampled as contact elements in the frame of its centre (the record's frame)."""
    hx, hy, hz = (0.5 * s for s in protocol.sole_size)
    face = "box" if faces == "box" else "sole"
    return box_collider(ColliderBoxCfg((-hx, hx), (-hy, hy), (-hz, hz), face, resolution))


def rft_sole_sand(collider: ColliderPoints, cfg: ContactRFT3DCfg, material: MaterialCfg) -> SoleSand:
    """Return a stateful sand: each call evaluates the reference forces, then advances the element memory."""
    state = [ExtState.zeros(collider.num_points)]

    def sand(pos: np.ndarray, rot: np.ndarray, lin_vel: np.ndarray, ang_vel: np.ndarray) -> np.ndarray:
        """Wrench of the sand on the sole this frame: force [N] and torque about the centre ``pos`` [N m], [6]."""
        r = collider.points @ rot.T
        x, n, v = pos + r, collider.normals @ rot.T, lin_vel + np.cross(ang_vel, r)
        f = rft3d_extended_forces(x, n, v, collider.areas, state[0], cfg, material)
        state[0] = advance_ext_state(state[0], x, n, v, cfg)
        return np.concatenate([f.sum(0), np.cross(r, f).sum(0)])

    return sand


def replay_wrench(
    record: SoleRecord, collider: ColliderPoints, cfg: ContactRFT3DCfg, material: MaterialCfg, dt: float
) -> np.ndarray:
    """Return the model's wrench along a recorded experiment, [T, 6] (the recorded kinematics, fresh memory).

    Columns: force [N], then torque about the sole-box centre [N m], world axes. ``dt`` is the record's frame time
    [s]: the added-mass acceleration is a difference over recorded frames.
    """
    cfg = replace(cfg, extensions=replace(cfg.extensions, dt=dt))
    sand = rft_sole_sand(collider, cfg, material)
    return np.stack([sand(*k) for k in zip(record.pos, record.rot, record.lin_vel, record.ang_vel, strict=True)])
