# SPDX-License-Identifier: Apache-2.0
"""Reduced-order box study: the box of :class:`BoxCfg` on MuJoCo C with a ``gmloco.contact`` model's wrench.

One MuJoCo model/data per trial, one contact model batched over all trials (num_worlds = trials, num_feet = 1).
Each physics step: box kinematics -> ``compute`` (force, torque about the CoM) -> ``xfrc_applied`` -> ``mj_step``
-> ``update_state`` with the same kinematics (the contact package's call order). The rigid baseline instead lets
MuJoCo's own box-plane contact act (friction mu_surf).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from gmloco.eval.box.config import BoxCfg

__all__ = ["ROM_MODELS", "RomBoxCfg", "RomBoxResult", "cone_sigmas", "make_box_contact_cfg", "simulate_rom_box"]

RomModelName = Literal["rigid", "heuristic_rft", "cone_single", "cone_multi", "rft3d"]
ROM_MODELS: tuple[str, ...] = ("rigid", "heuristic_rft", "cone_single", "cone_multi", "rft3d")
"""The reduced-order models of the study, as named in results tables."""

G_VERTICAL_SOLE = 0.8757
"""3D-RFT generic vertical stress of a horizontal plate pushed down, PNAS majority set [-] (spec 5.1 case A)."""
CONE_SIGMA_RATIO = 4.0e5 / 5.0e6
"""sigma_cone / sigma_flat of GM-Loco's cone defaults [-] (spec 3.1)."""


@dataclass(frozen=True)
class RomBoxCfg:
    """Reduced-order simulation of the box study."""

    box: BoxCfg = field(default_factory=BoxCfg)
    """The intruder."""
    dt: float = 0.005
    """Physics step [s] (200 Hz, as the training)."""
    log_dt: float = 0.01
    """GRF logging interval [s]; matches the MPM frame time so profiles compare sample by sample."""
    collider_resolution: int = 6
    """Collider cells per box edge on each of the six faces."""
    rft3d_coeffs: str | Path = "pnas"
    """3D-RFT coefficient set (name or fitted file, see ``gmloco.contact.load_rft3d_coeffs``)."""
    at_rest: Literal["none", "unloading", "ema"] = "none"
    """At-rest treatment of the granular models: ``"none"`` = the published models. The contact package's
    ``"unloading"`` branch (its training default) bounced the 35 kg box 0.13 m back up after impact here."""
    device: str = "cpu"
    """Warp device of the contact kernels."""


@dataclass
class RomBoxResult:
    """Trajectories of one model over all trials."""

    body_pos: np.ndarray
    """CoM position at each logged time [m], [W, T, 3]."""
    body_quat: np.ndarray
    """Orientation (w, x, y, z) at each logged time, [W, T, 4]."""
    grf: np.ndarray
    """Mean force of the medium on the box over each log interval [N], [W, T, 3]."""
    time: np.ndarray
    """Log times [s], [T] (end of each interval)."""
    wall_time: float
    """Wall-clock time of the whole batch [s]."""


def cone_sigmas(rho_c: np.ndarray, mu_int: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Map a medium to the cone model's (sigma_flat, sigma_cone) [N/m^3] (project choice, README).

    sigma_flat = 0.8757 xi_n makes the cone's flat-area stiffness equal 3D-RFT's for a horizontal plate pushed
    straight down; sigma_cone keeps GM-Loco's default ratio 0.08.
    """
    # here, not at the top: gmloco.contact pulls Warp; this module imports with numpy alone
    from gmloco.contact import xi_n

    flat = G_VERTICAL_SOLE * np.asarray(xi_n(np.asarray(rho_c), np.asarray(mu_int)), dtype=np.float64)
    return flat, CONE_SIGMA_RATIO * flat


def make_box_contact_cfg(model: str, cfg: RomBoxCfg) -> Any:
    """Return the contact-package configuration of ``model`` with the box as its (six-face) collider."""
    # here, not at the top: gmloco.contact pulls Warp; this module imports with numpy alone
    import gmloco.contact as gc

    hx, hy, hz = cfg.box.half_extents
    collider = gc.ColliderBoxCfg(
        x_range=(-hx, hx), y_range=(-hy, hy), z_range=(-hz, hz), faces="box", resolution=cfg.collider_resolution
    )
    if model == "rft3d":
        return gc.ContactRFT3DCfg(collider=collider, coeffs=cfg.rft3d_coeffs, at_rest=cfg.at_rest)
    if model == "heuristic_rft":
        return gc.ContactHeuristicRFTCfg(collider=collider, at_rest=cfg.at_rest)
    if model == "cone_single":
        return gc.ContactConeSingleCfg(collider=collider, at_rest=cfg.at_rest, dt=cfg.dt)
    if model == "cone_multi":
        return gc.ContactConeMultiCfg(collider=collider, at_rest=cfg.at_rest, dt=cfg.dt)
    if model == "rigid":
        return gc.ContactRigidCfg(collider=collider)
    raise ValueError(f"model={model!r}: expected one of {ROM_MODELS}")


def _box_xml(box: BoxCfg, dt: float, rigid: bool, mu_surf: float) -> str:
    """MJCF of the free box over a plane at z = 0 (the plane collides only in the rigid baseline)."""
    hx, hy, hz = box.half_extents
    con = 1 if rigid else 0
    return f"""<mujoco><option timestep="{dt}" gravity="0 0 -9.81" integrator="implicitfast"/>
<worldbody><geom type="plane" size="0 0 1" contype="{con}" conaffinity="{con}" friction="{mu_surf} 0.005 0.0001"/>
<body name="box"><freejoint/><geom type="box" size="{hx} {hy} {hz}" mass="{box.mass}" contype="{con}"
conaffinity="{con}" friction="{mu_surf} 0.005 0.0001"/></body></worldbody></mujoco>"""


def _kinematics(datas: list[Any]) -> tuple[np.ndarray, ...]:
    """Box pose and velocities from qpos/qvel (free joint: world linear velocity, body-frame angular)."""
    import mujoco

    n = len(datas)
    pos, mat, lin, ang = np.zeros((n, 3)), np.zeros((n, 9)), np.zeros((n, 3)), np.zeros((n, 3))
    for w, d in enumerate(datas):
        pos[w] = d.qpos[0:3]
        mujoco.mju_quat2Mat(mat[w], d.qpos[3:7])
        lin[w] = d.qvel[0:3]
        ang[w] = mat[w].reshape(3, 3) @ d.qvel[3:6]
    return pos, mat.reshape(n, 3, 3), lin, ang


def simulate_rom_box(
    model: str, cfg: RomBoxCfg, rho_c: np.ndarray, mu_int: np.ndarray, mu_surf: np.ndarray
) -> RomBoxResult:
    """Simulate the box under one reduced-order model for every trial material.

    Args:
        model: One of :data:`ROM_MODELS`.
        cfg: Simulation configuration.
        rho_c: Critical density per trial [kg/m^3], [W].
        mu_int: Internal friction per trial [-], [W].
        mu_surf: Surface friction per trial [-], [W].
    """
    # MuJoCo C, Warp and gmloco.contact load only when trials run; this module imports with numpy alone
    import mujoco
    import warp as wp

    import gmloco.contact as gc

    n = len(rho_c)
    box = cfg.box
    rigid = model == "rigid"
    contact = gc.make_contact_model(make_box_contact_cfg(model, cfg), n, 1, cfg.device)
    extra = dict(zip(("sigma_flat", "sigma_cone"), cone_sigmas(rho_c, mu_int), strict=True)) if "cone" in model else {}
    contact.set_materials(rho_c=rho_c, mu_int=mu_int, mu_surf=mu_surf, **extra)
    models = [mujoco.MjModel.from_xml_string(_box_xml(box, cfg.dt, rigid, float(m))) for m in mu_surf]
    datas = [mujoco.MjData(m) for m in models]
    for d in datas:
        d.qpos[0:3], d.qpos[3:7], d.qvel[0:3] = box.initial_pos, box.initial_quat_wxyz, box.initial_velocity
    dev = cfg.device
    arrs = {k: wp.zeros((n, 1), dtype=t, device=dev) for k, t in
            (("pos", wp.vec3), ("mat", wp.mat33), ("lin", wp.vec3), ("ang", wp.vec3), ("com", wp.vec3))}  # fmt: skip
    wrench = wp.zeros((n, 1), dtype=wp.spatial_vectorf, device=dev)  # = wp.spatial_vector, typed as a dtype class
    steps_per_log = max(1, round(cfg.log_dt / cfg.dt))
    num_logs = round(box.duration / cfg.log_dt)
    out_pos, out_quat, out_grf = np.zeros((n, num_logs, 3)), np.zeros((n, num_logs, 4)), np.zeros((n, num_logs, 3))
    weight = np.array([0.0, 0.0, -9.81 * box.mass])
    t0 = time.perf_counter()
    for k in range(num_logs):
        v_start = np.array([d.qvel[0:3] for d in datas])
        for _ in range(steps_per_log):
            pos, mat, lin, ang = _kinematics(datas)
            for key, val in (("pos", pos), ("mat", mat), ("lin", lin), ("ang", ang), ("com", pos)):
                arrs[key].assign(val[:, None])
            inputs = (arrs["pos"], arrs["mat"], arrs["lin"], arrs["ang"], arrs["com"])
            contact.compute(*inputs, wrench)
            w_np = wrench.numpy()[:, 0]
            for w, (m, d) in enumerate(zip(models, datas, strict=True)):
                d.xfrc_applied[1] = w_np[w]
                mujoco.mj_step(m, d)
            contact.update_state(*inputs)
        v_end = np.array([d.qvel[0:3] for d in datas])
        # mean force of the medium over the interval from the momentum balance m dv = (F + m g) dt
        out_grf[:, k] = box.mass * (v_end - v_start) / (steps_per_log * cfg.dt) - weight
        out_pos[:, k] = [d.qpos[0:3] for d in datas]
        out_quat[:, k] = [d.qpos[3:7] for d in datas]
    times = cfg.log_dt * np.arange(1, num_logs + 1)
    return RomBoxResult(out_pos, out_quat, out_grf, times, time.perf_counter() - t0)
