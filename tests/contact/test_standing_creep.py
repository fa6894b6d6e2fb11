# SPDX-License-Identifier: Apache-2.0
"""A PD-held G1 standing on 3D-RFT sand with the sole-only collider does not creep (static friction in the crater).

Harness: ``simulate_standing`` of packages/train/tests/test_standing_on_sand.py (plain MuJoCo C G1, pelvis on a
vertical slide, joints PD-held at HOME, 200 Hz, lowered onto the sand over 1 s), run longer and with the feet's
horizontal positions recorded. The pelvis cannot move sideways, so a foot that slides does so by bending the
PD-held legs: under the viscous-only crater friction (``static_friction=False``) a steady tangential load F_t
needs a steady slip speed F_t / (c_t A_sole) = 14 N / (1e4 N s/m^3 * 0.01516 m^2) ~ 9 cm/s, the feet creep
apart and the robot collapses after ~4 s. With the stick spring (Cundall-Strack, mobilization distance 2 mm) a
load below mu F_n is held by a static offset of at most 2 mm, so the feet stop.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

import mujoco
import numpy as np
import pytest
import warp as wp

from gmloco.contact import ContactRFT3DCfg, MaterialCfg, g1_foot_box_cfg, g1_foot_collider, make_contact_model
from tests.contact.by_path import load_module


def standing_harness() -> ModuleType:
    """Import packages/train/tests/test_standing_on_sand.py by path (its G1 model, pose, gains and inputs)."""
    return load_module("standing_on_sand_harness", "packages/train/tests/test_standing_on_sand.py")


@dataclass
class CreepResult:
    """Per-second statistics of a long standing run (window k covers [k, k + 1) s)."""

    foot_speed: np.ndarray
    """Largest horizontal foot speed over the window, from the displacement across it [m/s], [T]."""
    fz_std: np.ndarray
    """Standard deviation of the total vertical foot force over the window / weight [-], [T]."""
    fx_mean: np.ndarray
    """Mean |F_x| per foot over the window [N], [T]."""
    late_sinkage: float
    """Pelvis height at 3 s minus its height at the end [m] (sinking of the settled robot)."""


def simulate_creep(
    cfg: ContactRFT3DCfg, material: MaterialCfg, duration: float = 5.0, ramp: float = 1.0
) -> CreepResult:
    """Lower the G1 onto sand over ``ramp`` s, stand until ``duration`` s, and return per-second statistics."""
    h = standing_harness()
    model = h.build_g1_on_slide()
    data = mujoco.MjData(model)
    data.qpos[:] = h.home_qpos(model)
    data.ctrl[:] = data.qpos[model.jnt_qposadr[model.actuator_trnid[:, 0]]]
    feet = [model.body(name).id for name in h.FEET]
    mujoco.mj_kinematics(model, data)
    points_b = g1_foot_collider("sole", 2).points
    data.qpos[0] = -min((data.xpos[b] + points_b @ data.xmat[b].reshape(3, 3).T)[:, 2].min() for b in feet)
    contact = make_contact_model(cfg, 1, len(feet), "cpu")
    contact.set_materials([material.rho_c], [material.mu_int], [material.mu_surf])
    weight = float(model.body_subtreemass[1] * -model.opt.gravity[2])
    wrench = wp.zeros((1, len(feet)), dtype=wp.spatial_vectorf, device="cpu")
    n_ramp, n_total = round(ramp / h.DT), round(duration / h.DT)
    foot_xy, fz, fx, pelvis_z = [], [], [], []
    for step in range(n_total):
        mujoco.mj_step1(model, data)
        pos, rot, lin_vel, ang_vel, com = h._foot_inputs(model, data, feet)
        contact.compute(pos, rot, lin_vel, ang_vel, com, wrench)
        data.xfrc_applied[:] = 0.0
        data.xfrc_applied[feet] = wrench.numpy()[0]
        data.xfrc_applied[1, 2] = weight * max(0.0, 1.0 - step / n_ramp)  # support on the pelvis
        contact.update_state(pos, rot, lin_vel, ang_vel, com)
        mujoco.mj_step2(model, data)
        w = wrench.numpy()[0].copy()  # numpy() is a view of the Warp buffer on CPU
        foot_xy.append(data.xpos[feet, :2].copy())
        fz.append(w[:, 2].sum() / weight)
        fx.append(np.abs(w[:, 0]).mean())
        pelvis_z.append(float(data.qpos[0]))
    per_s = round(1.0 / h.DT)
    xy, fz_a, fx_a = np.array(foot_xy), np.array(fz), np.array(fx)
    windows = range(0, n_total - per_s + 1, per_s)
    return CreepResult(
        foot_speed=np.array([np.linalg.norm(xy[k + per_s - 1] - xy[k], axis=-1).max() / 1.0 for k in windows]),
        fz_std=np.array([fz_a[k : k + per_s].std() for k in windows]),
        fx_mean=np.array([fx_a[k : k + per_s].mean() for k in windows]),
        late_sinkage=pelvis_z[min(3 * per_s, n_total) - 1] - pelvis_z[-1],
    )


def sole_cfg(static_friction: bool) -> ContactRFT3DCfg:
    """Return the default 3D-RFT model on the sole-only 5 x 5 collider, with or without static friction."""
    return ContactRFT3DCfg(collider=g1_foot_box_cfg("sole", 5), static_friction=static_friction)


MEDIA = [
    "dry_sand",
    pytest.param("basalt", marks=pytest.mark.slow),
    pytest.param("poppy_seed", marks=pytest.mark.slow),
]


@pytest.mark.parametrize("material", MEDIA)
def test_standing_g1_does_not_creep(material: str) -> None:
    """Feet move < 1 mm/s over seconds 3-5 (viscous-only crater friction: ~9-10 cm/s, then collapse).

    Bounds: a held foot may still shift by the stick distance (2 mm) while its load changes, so 1 mm/s over a
    1 s window is a creep bound with margin; the force std stays < 10 % of the weight and the settled robot
    sinks by less than 1 mm over seconds 3-5.
    """
    from gmloco.contact import MATERIAL_PRESETS

    result = simulate_creep(sole_cfg(True), MATERIAL_PRESETS[material])
    assert result.foot_speed[3:].max() < 1e-3, result
    assert result.fz_std[3:].max() < 0.10, result
    assert abs(result.late_sinkage) < 0.001, result


def test_viscous_crater_friction_creeps() -> None:
    """The previous law (static_friction=False) lets the feet creep at > 5 cm/s on dry sand (the bug fixed)."""
    from gmloco.contact import MATERIAL_PRESETS

    result = simulate_creep(sole_cfg(False), MATERIAL_PRESETS["dry_sand"], duration=4.0)
    assert result.foot_speed[1:].min() > 0.05, result
