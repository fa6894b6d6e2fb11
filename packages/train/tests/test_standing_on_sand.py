# SPDX-License-Identifier: Apache-2.0
"""A PD-held G1 standing on granular contact settles (plain MuJoCo C, wrench applied through xfrc_applied).

Setup (issue 3, "Behaviour at rest"): the G1 MJCF shipped with mjlab (descends from MuJoCo Menagerie,
BSD-3-Clause), pelvis on a vertical slide so it cannot tip, all rigid contact disabled, joints PD-held at
mjlab's HOME pose with mjlab's G1 gains, 200 Hz. Each step the contact model's wrench is written into
``xfrc_applied`` between ``mj_step1`` (kinematics and velocities, where MuJoCo Warp's passive callback runs)
and ``mj_step2``; ``update_state`` then advances the model's memory with the same kinematics.

Protocol: soles start at the surface and a support force on the pelvis ramps from the full weight to zero
over ``ramp`` seconds (the robot is lowered onto the sand quasi-statically), then the robot settles for
``settle`` seconds and is measured for ``measure`` seconds.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import mujoco
import numpy as np
import pytest
import warp as wp

from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, g1_foot_box_cfg, g1_foot_collider, make_contact_model
from gmloco.contact.reference import rft3d_generic
from gmloco.deploy.g1 import G1_FOOT_BODIES, g1_mjcf_path

DT = 0.005
"""Physics step [s] (GM-Loco: 200 Hz)."""
FEET = G1_FOOT_BODIES
# mjlab 1.6 g1_constants: (joint regex, armature [kg m^2], kp [N m/rad], kd [N m s/rad], effort limit [N m]);
# kp = armature (2 pi 10 Hz)^2, kd = 2 * 2.0 * armature * (2 pi 10 Hz). Copied to avoid importing mjlab (~8 s).
G1_GAINS = (
    (r".*_(elbow|shoulder_pitch|shoulder_roll|shoulder_yaw|wrist_roll)_joint", 0.003609725, 14.2506, 0.90722, 25.0),
    (r".*_hip_pitch_joint|.*_hip_yaw_joint|waist_yaw_joint", 0.01017752, 40.1792, 2.55789, 88.0),
    (r".*_hip_roll_joint|.*_knee_joint", 0.025101925, 99.0984, 6.30880, 139.0),
    (r".*_wrist_(pitch|yaw)_joint", 0.00425, 16.7783, 1.06814, 5.0),
    (r"waist_(pitch|roll)_joint|.*_ankle_(pitch|roll)_joint", 0.00721945, 28.5012, 1.81445, 50.0),
)
HOME_POSE = {
    ".*_hip_pitch_joint": -0.1,
    ".*_knee_joint": 0.3,
    ".*_ankle_pitch_joint": -0.2,
    ".*_shoulder_pitch_joint": 0.2,
    ".*_elbow_joint": 1.28,
    "left_shoulder_roll_joint": 0.2,
    "right_shoulder_roll_joint": -0.2,
}


def build_g1_on_slide() -> mujoco.MjModel:
    """Return the G1 with its free joint replaced by a vertical slide, PD position actuators, no contact."""
    spec = mujoco.MjSpec.from_file(str(g1_mjcf_path()))
    pelvis = spec.body("pelvis")
    spec.delete(pelvis.joints[0])
    pelvis.add_joint(name="slide_z", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0.0, 0.0, 1.0])
    spec.option.timestep = DT
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT  # foot-ground rigid contact off
    for joint in spec.joints:
        if joint.type != mujoco.mjtJoint.mjJNT_HINGE:
            continue
        _, armature, kp, kd, limit = next(g for g in G1_GAINS if re.fullmatch(g[0], joint.name))
        joint.armature = armature
        act = spec.add_actuator(name=joint.name, target=joint.name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.gainprm[0] = kp
        act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        act.biasprm[:3] = [0.0, -kp, -kd]
        act.forcelimited = True
        act.forcerange = [-limit, limit]
    return spec.compile()


def home_qpos(model: mujoco.MjModel) -> np.ndarray:
    """Return qpos of mjlab's HOME pose (slide at 0)."""
    qpos = np.zeros(model.nq)
    for j in range(model.njnt):
        name = model.joint(j).name
        for pattern, value in HOME_POSE.items():
            if re.fullmatch(pattern, name):
                qpos[model.jnt_qposadr[j]] = value
    return qpos


@dataclass
class StandingResult:
    """Statistics of the measurement window."""

    weight: float
    """Robot weight m g [N]."""
    fz_mean: float
    """Mean total vertical foot force [N]."""
    fz_std: float
    """Standard deviation of the total vertical foot force [N]."""
    fxy_std: float
    """Largest per-foot standard deviation of a horizontal force component [N]."""
    sinkage: float
    """Mean sole depth over both feet [m]."""
    sinkage_static: float
    """Static prediction W / (2 G_z A xi) for a flat sole carrying half the weight [m]."""


def simulate_standing(
    cfg: ContactRFT3DCfg, material: str = "dry_sand", ramp: float = 1.0, settle: float = 1.0, measure: float = 1.0
) -> StandingResult:
    """Lower the G1 onto sand, let it settle, and return force and sinkage statistics."""
    model = build_g1_on_slide()
    data = mujoco.MjData(model)
    data.qpos[:] = home_qpos(model)
    data.ctrl[:] = data.qpos[model.jnt_qposadr[model.actuator_trnid[:, 0]]]
    feet = [model.body(name).id for name in FEET]
    mujoco.mj_kinematics(model, data)
    points_b = g1_foot_collider("sole", 2).points
    sole_z = [(data.xpos[b] + points_b @ data.xmat[b].reshape(3, 3).T)[:, 2].min() for b in feet]
    data.qpos[0] = -min(sole_z)  # lowest sole point at the free surface z = 0
    mat = MATERIAL_PRESETS[material]
    contact = make_contact_model(cfg, 1, len(feet), "cpu")
    contact.set_materials([mat.rho_c], [mat.mu_int], [mat.mu_surf])
    weight = float(model.body_subtreemass[1] * -model.opt.gravity[2])
    wrench = wp.zeros((1, len(feet)), dtype=wp.spatial_vector, device="cpu")
    n_ramp, n_settle, n_measure = (round(t / DT) for t in (ramp, settle, measure))
    fz, fxy, depth = [], [], []
    for step in range(n_ramp + n_settle + n_measure):
        mujoco.mj_step1(model, data)
        inputs = _foot_inputs(model, data, feet)
        contact.compute(*inputs, wrench)
        data.xfrc_applied[:] = 0.0
        data.xfrc_applied[feet] = wrench.numpy()[0]
        data.xfrc_applied[1, 2] = weight * max(0.0, 1.0 - step / n_ramp)  # support on the pelvis
        contact.update_state(*inputs)
        mujoco.mj_step2(model, data)
        if step >= n_ramp + n_settle:
            w = wrench.numpy()[0].copy()  # numpy() is a view of the Warp buffer on CPU
            fz.append(w[:, 2].sum())
            fxy.append(w[:, :2])
            depth.append(contact.point_depth.numpy()[0].mean())
    sole_area = np.prod(np.diff(cfg.collider.x_range)) * np.prod(np.diff(cfg.collider.y_range))
    g_z = rft3d_generic(np.array([[0.0, 0.0, -1.0]]), np.zeros((1, 3)), cfg.coeffs)[0, 2]
    return StandingResult(
        weight=weight,
        fz_mean=float(np.mean(fz)),
        fz_std=float(np.std(fz)),
        fxy_std=float(np.max(np.std(np.array(fxy), axis=0))),
        sinkage=float(np.mean(depth)),
        sinkage_static=float(0.5 * weight / (g_z * mat.xi * sole_area)),
    )


def _foot_inputs(model: mujoco.MjModel, data: mujoco.MjData, feet: list[int]) -> tuple[wp.array, ...]:
    """Return (pos, rot, lin_vel at the frame origin, ang_vel, com) of the feet as [1, F] Warp arrays."""
    vel = np.zeros((len(feet), 6))
    for i, b in enumerate(feet):
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, b, vel[i], 0)  # (ang, lin), world axes
    arrays = (data.xpos[feet], data.xmat[feet].reshape(-1, 3, 3), vel[:, 3:], vel[:, :3], data.xipos[feet])
    types = (wp.vec3, wp.mat33, wp.vec3, wp.vec3, wp.vec3)
    return tuple(
        wp.array(a[None].astype(np.float32), dtype=t, device="cpu") for a, t in zip(arrays, types, strict=True)
    )


@pytest.mark.parametrize("material", ["dry_sand", "basalt", "poppy_seed"])
def test_g1_settles_on_sand(material: str) -> None:
    """A PD-held G1 settles on 3D-RFT sand: force std < 10 % of weight, sinkage within 20 % of static.

    Static prediction: each flat sole carries W/2 = G_z xi A d with G_z = 0.8757 (spec 5.1 case A),
    A = 0.206 * 0.0736 m^2; on dry sand xi = 1500 * 9.81 * f(0.6) = 1.58e6 N/m^3 so d ~ 7.8 mm for the
    33.3 kg G1 (basalt 1.4 mm, poppy seed 31 mm). The published model (at_rest="none") fails both bounds
    (dry sand: 327 +- 264 N, 3.0x static sinkage; packages/contact/scripts/at_rest_comparison.py).
    """
    result = simulate_standing(ContactRFT3DCfg(collider=g1_foot_box_cfg("sole", 5)), material=material)
    np.testing.assert_allclose(result.fz_mean, result.weight, rtol=0.05)
    assert result.fz_std < 0.10 * result.weight, result
    np.testing.assert_allclose(result.sinkage, result.sinkage_static, rtol=0.20)
