# SPDX-License-Identifier: Apache-2.0
"""Impact dissipation of the at-rest branch: a box dropped on sand must not bounce (README, "At rest").

One rigid body, vertical translation only, integrated with semi-implicit Euler at 200 Hz (m z'' = F_z - m g, the
explicit coupling of the training): the box study's 35 kg, 0.3 x 0.3 x 0.2 m box with a six-face collider, released
with its bottom 0.1 m above the surface. No MuJoCo needed.
"""

from __future__ import annotations

import numpy as np
import pytest
import warp as wp

from gmloco.contact import MATERIAL_PRESETS, ColliderBoxCfg, ContactRFT3DCfg, make_contact_model

DT = 0.005
MASS = 35.0
HALF = (0.15, 0.15, 0.1)
DROP = 0.1
G = 9.81


def drop_box(cfg: ContactRFT3DCfg, material: str, device: str, duration: float = 1.5) -> np.ndarray:
    """Return the CoM height [m] after each step of a vertical drop onto a flat bed at z = 0."""
    model = make_contact_model(cfg, 1, 1, device)
    mat = MATERIAL_PRESETS[material]
    model.set_materials([mat.rho_c], [mat.mu_int], [mat.mu_surf])
    z, v_z = HALF[2] + DROP, 0.0
    rot = wp.array(np.eye(3, dtype=np.float32)[None, None], dtype=wp.mat33, device=device)
    zero = wp.zeros((1, 1), dtype=wp.vec3, device=device)
    wrench = wp.zeros((1, 1), dtype=wp.spatial_vector, device=device)
    heights = []
    for _ in range(round(duration / DT)):
        pos = wp.array(np.array([[[0.0, 0.0, z]]], dtype=np.float32), dtype=wp.vec3, device=device)
        vel = wp.array(np.array([[[0.0, 0.0, v_z]]], dtype=np.float32), dtype=wp.vec3, device=device)
        inputs = (pos, rot, vel, zero, pos)
        model.compute(*inputs, wrench)
        model.update_state(*inputs)
        v_z += DT * (float(wrench.numpy()[0, 0, 2]) / MASS - G)
        z += DT * v_z
        heights.append(z)
    return np.array(heights)


def rebound(heights: np.ndarray) -> tuple[float, float]:
    """Return (rise of the CoM above its settled height after the first deepest point [m], e = v_up / v_impact)."""
    j = int(np.argmax(heights < HALF[2]))
    while j + 1 < len(heights) and heights[j + 1] <= heights[j]:
        j += 1
    rise = float(heights[j:].max() - heights[-40:].mean())
    return rise, float(np.sqrt(2.0 * G * max(rise, 0.0)) / np.sqrt(2.0 * G * DROP))


BOX = ColliderBoxCfg(x_range=(-HALF[0], HALF[0]), y_range=(-HALF[1], HALF[1]), z_range=(-HALF[2], HALF[2]), faces="box")


@pytest.mark.parametrize("material", ["dry_sand", "poppy_seed"])
def test_box_drop_does_not_rebound(material: str, device: str) -> None:
    """Default at-rest branch: the box rises < 5 mm above where it settles and e <= 0.1; it comes to rest."""
    heights = drop_box(ContactRFT3DCfg(collider=BOX), material, device)
    rise, e = rebound(heights)
    assert rise < 0.005 and e <= 0.1, (rise, e)
    assert np.ptp(heights[-40:]) < 1e-3  # settled
    assert heights[-1] < HALF[2]  # resting in the bed, not on top of it


def test_elastic_unloading_without_impact_damping_rebounds(device: str) -> None:
    """Control: the old default (unloading_speed = 0, elastic line at the loading stiffness) bounces the box back."""
    rise, e = rebound(drop_box(ContactRFT3DCfg(collider=BOX, unloading_speed=0.0), "dry_sand", device))
    assert e > 0.5, (rise, e)
