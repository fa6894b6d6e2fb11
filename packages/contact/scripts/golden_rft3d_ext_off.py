# SPDX-License-Identifier: Apache-2.0
"""Write the golden wrenches of a press-lift-press-drag foot trajectory under the published 3D-RFT.

Run against a contact package without the extension terms (commit 446cd8e) to pin that ``RftExtensionsCfg()`` (all
off) leaves the model bit for bit unchanged (``tests/test_rft3d_extensions.py::test_extensions_off_equal_golden``):

    mkdir -p /tmp/c && git archive 446cd8e packages/contact/src | tar -x -C /tmp/c
    PYTHONPATH=/tmp/c/packages/contact/src python packages/contact/scripts/golden_rft3d_ext_off.py \
        packages/contact/tests/golden_data/rft3d_extensions_off
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import warp as wp

import gmloco.contact as gc

NUM_WORLDS, NUM_FEET, STEPS, DT = 2, 2, 48, 0.005


def trajectory() -> tuple[np.ndarray, ...]:
    """Return (pos, rot, lin_vel, ang_vel, com) [STEPS, W, F, ...]: press 20 mm, lift 6 mm, press to 30 mm, drag."""
    rng = np.random.default_rng(3)
    v_z = np.concatenate([np.full(12, -0.4), np.full(14, 0.3), np.full(22, -0.4)])
    v_x = np.where(np.arange(STEPS) >= 30, 0.2, 0.0)
    sole = 0.03539
    z = sole + 0.002 + np.concatenate([[0.0], np.cumsum(v_z[:-1] * DT)])
    x = np.concatenate([[0.0], np.cumsum(v_x[:-1] * DT)])
    tilt = rng.normal(scale=0.05, size=(NUM_WORLDS, NUM_FEET, 3))
    pos = np.zeros((STEPS, NUM_WORLDS, NUM_FEET, 3))
    pos[..., 0] = x[:, None, None] + 0.3 * np.arange(NUM_FEET)[None, None, :]
    pos[..., 2] = z[:, None, None]
    rot = np.zeros((STEPS, NUM_WORLDS, NUM_FEET, 3, 3))
    for w in range(NUM_WORLDS):
        for f in range(NUM_FEET):
            a, b, _ = tilt[w, f]
            r_x = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
            r_y = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
            rot[:, w, f] = r_y @ r_x
    vel = np.zeros_like(pos)
    vel[..., 0], vel[..., 2] = v_x[:, None, None], v_z[:, None, None]
    ang = np.zeros_like(pos)
    return pos, rot, vel, ang, pos.copy()


def run_model(cfg: gc.ContactRFT3DCfg, fused: bool) -> tuple[np.ndarray, np.ndarray]:
    """Return (wrenches [STEPS, W, F, 6], point forces [STEPS, W, F, P, 3]) of compute_and_update_state."""
    model = gc.make_contact_model(cfg, NUM_WORLDS, NUM_FEET, "cpu")
    model.fused = fused
    out = wp.zeros((NUM_WORLDS, NUM_FEET), dtype=wp.spatial_vector, device="cpu")
    types = (wp.vec3, wp.mat33, wp.vec3, wp.vec3, wp.vec3)
    wrenches, points = [], []
    for step in zip(*trajectory(), strict=True):
        arrays = [wp.array(a.astype(np.float32), dtype=t, device="cpu") for a, t in zip(step, types, strict=True)]
        model.compute_and_update_state(*arrays, out)
        wrenches.append(out.numpy().copy())
        points.append(model.point_force.numpy().copy())
    return np.stack(wrenches), np.stack(points)


CASES: dict[str, gc.ContactRFT3DCfg] = {
    "none": gc.ContactRFT3DCfg(collider=gc.g1_foot_box_cfg("box", 3), at_rest="none"),
    "unloading": gc.ContactRFT3DCfg(collider=gc.g1_foot_box_cfg("box", 3)),
}
"""Published-model configurations the golden data covers (``at_rest`` none and the project default)."""


def main(out_dir: str) -> None:
    """Write ``<case>_<fused|unfused>_wrench.npy`` and ``<case>_unfused_points.npy`` for every case of :data:`CASES`."""
    wp.config.quiet = True
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for name, cfg in CASES.items():
        for fused in (True, False):
            wrench, points = run_model(cfg, fused)
            tag = f"{name}_{'fused' if fused else 'unfused'}"
            np.save(out / f"{tag}_wrench.npy", wrench.astype(np.float32))
            if not fused:  # the fused path's point forces equal these (tests/test_fused.py)
                np.save(out / f"{tag}_points.npy", points.astype(np.float32))


if __name__ == "__main__":
    main(sys.argv[1])
