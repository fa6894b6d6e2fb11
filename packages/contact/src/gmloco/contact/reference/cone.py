# SPDX-License-Identifier: Apache-2.0
"""Jammed-granular-cone RFT (Choi et al., Sci. Robotics 8 eadf1960, 2023), GM-Loco closed form [spec 3]."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

__all__ = [
    "ConeParams",
    "ConeState",
    "cone_flat_area",
    "cone_multi_quasi_static_force",
    "cone_quasi_static_force",
    "cone_step",
]


@dataclass(frozen=True)
class ConeParams:
    """Cone-model parameters (GM-Loco ``DefaultConeDRFTCfg`` defaults)."""

    r_h: float = 0.05423
    """Hydraulic radius of the contact patch [m]."""
    sigma_flat: float = 5.0e6
    """Stress per depth on the flat (jammed-cone base) area [N/m^3]."""
    sigma_cone: float = 4.0e5
    """Stress per depth on the cone flank area [N/m^3]."""
    nu: float = 1.0
    """Recruitment rate [-]."""
    theta: float = 0.5236
    """Shear-band angle [rad]."""
    c_g: float = 1.0
    """Surrounding-mass factor [-]."""
    c_d: float = 1.0
    """Drag factor [-]."""
    packing: float = 0.6
    """Packing fraction phi [-]."""
    grain_density: float = 638.0
    """Grain density rho [kg/m^3]."""
    eps_f: float = 1e-4
    """Plastic-unloading tolerance on z_max [m]."""
    mu: float = 0.5
    """Coulomb friction coefficient [-]."""
    k_f: float = 10.0
    """Tangential viscous cap [N s/m]."""
    unloading_ratio: float = 0.0
    """Elastic unloading stiffness / secant loading stiffness [-]; 0 = plastic (force 0) as published."""


@dataclass(frozen=True)
class ConeState:
    """Per-point state of the stateful cone model."""

    z_max: float = 0.0
    """Maximum depth since entering the medium [m]."""


def _k(p: ConeParams) -> float:
    """Return the cone contraction rate k = nu / tan(theta) [-]."""
    return p.nu / math.tan(p.theta)


def cone_flat_area(z: np.ndarray | float, p: ConeParams) -> np.ndarray:
    """Return A_flat(z) = pi (r_h - k z)^2, zero once z >= z_c = r_h / k [m^2]."""
    r = np.maximum(p.r_h - _k(p) * np.asarray(z, dtype=np.float64), 0.0)
    return np.pi * r**2


def cone_quasi_static_force(z: np.ndarray | float, p: ConeParams) -> np.ndarray:
    """Return F_qs(z) = sigma_flat I_flat + sigma_cone I_cone [N] (GM-Loco closed form, spec 3.1).

    I_flat = (pi / 3k)(r_h^3 - (r_h - k z_clip)^3), z_clip = min(z, z_c); I_cone = (pi r_h^2 z - I_flat)/cos(theta).
    """
    k = _k(p)
    z = np.maximum(np.asarray(z, dtype=np.float64), 0.0)
    z_clip = np.minimum(z, p.r_h / k)
    i_flat = np.pi / (3 * k) * (p.r_h**3 - (p.r_h - k * z_clip) ** 3)
    i_cone = (np.pi * p.r_h**2 * z - i_flat) / math.cos(p.theta)
    return p.sigma_flat * i_flat + p.sigma_cone * i_cone


def cone_multi_quasi_static_force(z: np.ndarray | float, p: ConeParams, num_points: int) -> np.ndarray:
    """Return the Cone-RFT-Multi quasi-static force of ``num_points`` points at equal depth [N]."""
    return num_points * cone_quasi_static_force(z, p)


def cone_step(z: float, z_dot: float, v_t: np.ndarray, state: ConeState, p: ConeParams) -> tuple[np.ndarray, ConeState]:
    """Advance one point of the stateful cone model one step (GM-Loco rule, added mass off).

    The normal force F = F_qs(z) + c_d M A_flat(z) z_dot^2 (z_dot > 0), M = c_g phi rho nu, acts while
    z_dot > 0 or z >= z_max - eps_f, clamped >= 0; otherwise it is 0 (plastic) or, when unloading_ratio r > 0,
    F_qs(z_max) max(0, 1 - r (z_max - z) / z_max) (elastic unloading). Tangential: Coulomb
    -min(mu F, k_f |v_t|) v_t / |v_t|.

    Args:
        z: Depth [m] (> 0 submerged).
        z_dot: Depth rate [m/s] (= -v_z).
        v_t: Horizontal velocity [m/s], shape [2] or [3] (z ignored).
        state: State before the step (z_max excludes this step's depth).
        p: Parameters.

    Returns:
        The force [N] (xyz) and the new state.
    """
    if z <= 0.0:
        return np.zeros(3), replace(state, z_max=0.0)
    z_max = state.z_max
    mass_rate = p.c_g * p.packing * p.grain_density * p.nu
    if z_dot > 0.0 or z >= z_max - p.eps_f:
        drag = p.c_d * mass_rate * float(cone_flat_area(z, p)) * z_dot**2 if z_dot > 0.0 else 0.0
        f_n = max(0.0, float(cone_quasi_static_force(z, p)) + drag)
    elif p.unloading_ratio > 0.0:
        f_n = float(cone_quasi_static_force(z_max, p)) * max(0.0, 1.0 - p.unloading_ratio * (z_max - z) / z_max)
    else:
        f_n = 0.0
    vt = np.array([v_t[0], v_t[1], 0.0])
    speed = float(np.linalg.norm(vt))
    f_t = -min(p.mu * f_n, p.k_f * speed) * vt / speed if speed > 0.0 else np.zeros(3)
    return f_t + np.array([0.0, 0.0, f_n]), replace(state, z_max=max(z_max, z))
