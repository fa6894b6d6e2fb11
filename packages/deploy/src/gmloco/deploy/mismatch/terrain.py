# SPDX-License-Identifier: Apache-2.0
"""Terrain effects: parametric changes of the nominal ground's stress law at the foot sole, zero at zero.

On the **sand** ground (3D-RFT, :mod:`gmloco.deploy.mismatch.sand`) the effects change the RFT cell forces
``F_i`` (:func:`sand_effect_forces`): ``zeta`` scales them, ``F_i (1 + zeta)`` (medium scale / packing,
alpha -> (1 + zeta) alpha); ``kappa`` hardens them with depth, ``F_i (1 + kappa z_i)``; the drag and cohesion laws
below are added to the vertical force of every submerged cell.

On the **plane** ground (MuJoCo soft contact, :mod:`gmloco.deploy.mismatch.g1model`) each terrain
effect adds a vertical force per sole point i (area ``A_i``, depth ``z_i > 0`` below the surface, vertical
velocity ``v_i``), exactly zero at zero parameters:

* ``terrain.stiffness_scale``: ``zeta * alpha_ref * A_i * z_i`` (RFT depth-linear law scaled, Li, Zhang &
  Goldman, Science 339:1408, 2013, eq. 1);
* ``terrain.depth_hardening``: ``alpha_ref * kappa * A_i * z_i^2`` (Bekker-type convexity);
* ``terrain.rate_drag``: ``rho_drag * A_i * v_i^2`` while intruding (``v_i < 0``; inertial drag, Roth, Han &
  Jaeger, arXiv 1910.10358);
* ``terrain.cohesion``: ``-c * A_i * tanh(z_i / z_c)`` (adhesion pulling the foot down; Mohr-Coulomb cohesion).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["TerrainEffectCfg", "TerrainParams", "sand_effect_forces", "sole_forces"]


@dataclass
class TerrainEffectCfg:
    """Constants of the terrain effect laws of the replay (``TerrainParams`` holds the effects themselves)."""

    alpha_ref: float = 8.0e6
    """Reference depth-stress coefficient [N/m^3], close to the nominal soft contact's effective stiffness per
    area (standing sinkage ~3 mm under 343 N on two 0.009 m^2 soles)."""
    point_area: float = 0.175 * 0.05 / 8
    """Sole area represented by each of the 8 sole points [m^2]."""
    cohesion_depth: float = 0.001
    """Depth over which cohesion builds up, ``z_c`` [m] (smooths the contact onset)."""
    surface_z: float = 0.0
    """Free-surface height [m]."""


@dataclass
class TerrainParams:
    """Terrain effect parameters (all zero: nominal)."""

    zeta: float = 0.0
    """Added depth-linear stress, fraction of ``alpha_ref`` [-]."""
    kappa: float = 0.0
    """Depth-hardening coefficient [1/m]."""
    rho_drag: float = 0.0
    """Inertial drag coefficient [kg/m^3]."""
    cohesion: float = 0.0
    """Adhesion stress [Pa]."""

    def active(self) -> bool:
        """Whether any law is non-zero."""
        return any(v != 0.0 for v in (self.zeta, self.kappa, self.rho_drag, self.cohesion))


def sole_forces(points_z: np.ndarray, vel_z: np.ndarray, p: TerrainParams, cfg: TerrainEffectCfg) -> np.ndarray:
    """Return the added vertical force on each sole point [N], shape like ``points_z``.

    Args:
        points_z: Sole-point heights [m], any shape.
        vel_z: Sole-point vertical velocities [m/s], same shape.
        p: Effect parameters.
        cfg: Law constants.
    """
    z = np.maximum(cfg.surface_z - points_z, 0.0)
    a = cfg.point_area
    f = cfg.alpha_ref * a * (p.zeta * z + p.kappa * z * z)
    f = f + p.rho_drag * a * np.where(vel_z < 0.0, vel_z * vel_z, 0.0) * (z > 0.0)
    f = f - p.cohesion * a * np.tanh(z / cfg.cohesion_depth)
    return f


def sand_effect_forces(
    f: np.ndarray, depth: np.ndarray, vel_z: np.ndarray, area: np.ndarray, p: TerrainParams, cfg: TerrainEffectCfg
) -> np.ndarray:
    """Return the RFT cell forces changed by the terrain effects [N], shape [K, 3] (``f`` itself at zero).

    Args:
        f: Nominal 3D-RFT forces on the sole cells [N], shape [K, 3].
        depth: Cell depths below the free surface [m], shape [K].
        vel_z: Cell vertical velocities [m/s], shape [K].
        area: Cell areas [m^2], shape [K].
        p: Effect parameters.
        cfg: Law constants (cohesion depth).
    """
    if not p.active():
        return f
    f = f * (1.0 + p.zeta + p.kappa * np.maximum(depth, 0.0))[:, None]
    inside = depth > 0.0
    fz = p.rho_drag * area * np.where(vel_z < 0.0, vel_z * vel_z, 0.0) * inside
    fz = fz - p.cohesion * area * np.tanh(np.maximum(depth, 0.0) / cfg.cohesion_depth)
    f[:, 2] += fz
    return f
