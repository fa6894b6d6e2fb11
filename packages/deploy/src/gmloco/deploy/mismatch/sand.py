# SPDX-License-Identifier: Apache-2.0
"""The project's 3D-RFT sand on the two G1 soles, as the nominal ground of the replay simulator.

The force law is the one of :mod:`gmloco.contact` (Agarwal, Goldman & Kamrin, PNAS 2023, with the project's
elastic unloading branch and crater static friction, ``gmloco.contact.reference.rft3d_unloading_forces``),
written out here for the sole only, so that one physics step costs tens of microseconds instead of hundreds:

* the sole of each foot is the project's collider (``g1_foot_collider``, 5 x 5 cells), all cells of one foot
  share the outward normal, so the static resistance ``alpha_s = alpha(n, g_hat)`` is computed once per foot;
* the element state is reset at every shooting-segment start: the maximum depth ``z_max`` of each cell comes
  from the replayer's crater memory (the sole cells moved kinematically along the logged motion,
  ``Replayer.crater_memory``), and every submerged cell is anchored where it is;
* the EMA reversal counter of the training kernels is not modelled: impact damping is always on.

Terrain effects (:mod:`gmloco.deploy.mismatch.terrain`) are parametric changes of this law, exactly nominal at
zero. ``gmloco.contact`` is imported lazily: the deploy package stays light for log reading.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SandCfg", "SoleRFT"]


@dataclass
class SandCfg:
    """Nominal sand of the replay simulator (defaults: ``gmloco.contact.ContactRFT3DCfg``)."""

    material: str = "dry_sand"
    """Material preset (``gmloco.contact.MATERIAL_PRESETS``)."""
    resolution: int = 5
    """Sole cells per edge of the foot collider [-]."""
    coeffs: str = "pnas"
    """3D-RFT coefficient set."""
    unloading_ratio: float = 1.0
    """Elastic unloading stiffness over the loading stiffness [-]."""
    unloading_damping: float = 0.001
    """Kelvin-Voigt time constant of the elastic branch [s]."""
    unloading_speed: float = 0.15
    """Impact-damping speed u0 of the elastic branch [m/s]."""
    tangential_damping: float = 1.0e4
    """Viscous tangential coefficient of the elastic branch per area [N*s/m^3]."""
    stick_distance: float = 0.002
    """Mobilisation distance of the crater static friction [m]."""
    v_eps: float = 1e-4
    """Speed below which the motion direction is gravity's [m/s]."""
    surface_z: float = 0.0
    """Free-surface height [m]."""


_G = np.array([0.0, 0.0, -1.0])


class SoleRFT:
    """3D-RFT forces on the two soles, with per-element elastic state."""

    def __init__(self, cfg: SandCfg | None = None) -> None:
        """Load the collider, coefficients and material."""
        # here, not at the top: gmloco.contact pulls Warp; deploy's light core imports without it
        from gmloco.contact import MATERIAL_PRESETS, g1_foot_collider
        from gmloco.contact.coefficients import RFT3D_MONOMIAL_POWERS, resolve_rft3d_coeffs

        self.cfg = cfg = cfg or SandCfg()
        col = g1_foot_collider("sole", cfg.resolution)
        self.points_body = np.asarray(col.points, float)
        """Sole cell centres in the ankle-roll frame [m], shape [M, 3]."""
        self.cell_area = np.asarray(col.areas, float)
        """Cell areas of one sole [m^2], shape [M]."""
        self.m = len(self.points_body)
        mat = MATERIAL_PRESETS[cfg.material]
        self.xi, self.mu = mat.xi, mat.mu_surf
        self._c = resolve_rft3d_coeffs(cfg.coeffs)
        self._pw = np.asarray(RFT3D_MONOMIAL_POWERS)  # [20, 3] integer powers
        self.zmax = np.zeros(2 * self.m)
        self.anchor = np.zeros((2 * self.m, 3))

    def area(self, feet: int) -> np.ndarray:
        """Cell areas of ``feet`` soles stacked foot after foot [m^2], shape [feet M]."""
        return np.tile(self.cell_area, feet)

    def reset(self, points: np.ndarray, zmax: np.ndarray | None = None) -> None:
        """Start a segment: every submerged cell anchored in place, its crater depth from ``zmax`` (or its depth).

        Args:
            points: Cell centres of the soles in the world frame [m], shape [F M, 3], foot after foot.
            zmax: Remembered maximum depth per cell [m], shape [F M]; never below the present depth.
        """
        depth = np.maximum(self.cfg.surface_z - points[:, 2], 0.0)
        self.zmax = depth if zmax is None else np.where(depth > 0.0, np.maximum(depth, zmax), 0.0)
        self.anchor = points.copy()

    def _alpha(self, n_e: np.ndarray, v_hat: np.ndarray, n: np.ndarray) -> np.ndarray:
        """Alpha [N/m^3] for effective normals ``n_e``, motion directions and outward normals, shape [K, 3].

        PNAS 2023 eq. 3: G = f1 n_e + f2 v_hat + f3 g_hat with cubic f_j of x1 = g_hat.v_hat, x2 = g_hat.n_e,
        x3 = n_e.v_hat, then alpha = xi [G_n + min(1, mu |G_n| / |G_t|) G_t] (surface-friction limit).
        """
        x1, x2 = -v_hat[:, 2], -n_e[:, 2]
        x3 = n_e[:, 0] * v_hat[:, 0] + n_e[:, 1] * v_hat[:, 1] + n_e[:, 2] * v_hat[:, 2]
        p1, p2, p3 = (np.stack([np.ones_like(x), x, x * x, x * x * x]) for x in (x1, x2, x3))  # [4, K]
        pw = self._pw
        mono = p1[pw[:, 0]] * p2[pw[:, 1]] * p3[pw[:, 2]]  # [20, K]
        f = self._c.T @ mono  # [3, K]
        g = f[0][:, None] * n_e + f[1][:, None] * v_hat
        g[:, 2] -= f[2]
        gn_s = np.einsum("ij,ij->i", g, n)
        gn = gn_s[:, None] * n
        gt = g - gn
        gt_norm = np.sqrt(np.einsum("ij,ij->i", gt, gt))
        s = np.minimum(1.0, self.mu * np.abs(gn_s) / (gt_norm + 1e-6))
        return self.xi * (gn + s[:, None] * gt)

    def forces(self, points: np.ndarray, vel: np.ndarray, normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return the sand forces on the cells [N] and their depths [m], and advance the element state.

        Args:
            points: Cell centres in the world frame [m], shape [F M, 3], foot after foot.
            vel: Cell velocities in the world frame [m/s], shape [F M, 3].
            normals: Outward sole normal of each foot in the world frame, shape [F, 3].

        Returns:
            Forces of the medium on the cells, shape [F M, 3], and depths below the surface, shape [F M].
        """
        cfg, m, nf = self.cfg, self.m, len(normals)
        area = self.area(nf)
        n = np.repeat(normals, m, axis=0)
        depth = cfg.surface_z - points[:, 2]
        sp = np.linalg.norm(vel, axis=1, keepdims=True)
        v_hat = np.where(sp < cfg.v_eps, _G, vel / np.maximum(sp, 1e-300))
        n_e = np.where(n[:, 2:3] < 0.0, n, -n)
        # one pass for the cells' alpha and, per foot, the static alpha_s = alpha(n, v_hat = g_hat)
        alpha = self._alpha(
            np.concatenate([n_e, n_e[::m]]), np.concatenate([v_hat, np.tile(_G, (nf, 1))]), np.concatenate([n, normals])
        )
        alpha_s = np.repeat(alpha[-nf:], m, axis=0)
        alpha = alpha[:-nf]
        active = (depth > 0.0) & (np.sum(n * v_hat, 1) >= 0.0)
        plastic = np.where(active[:, None], alpha * (depth * area)[:, None], 0.0)
        # elastic unloading branch inside the crater (gmloco.contact.reference.rft3d_unloading_forces)
        r, zm = cfg.unloading_ratio, self.zmax
        d_eff = np.maximum(0.0, zm - r * (zm - depth) - cfg.unloading_damping * r * vel[:, 2])
        d_eff = np.clip(d_eff * (1.0 - vel[:, 2] / cfg.unloading_speed), 0.0, zm)
        f_el = alpha_s * (d_eff * area)[:, None]
        limit = self.mu * np.abs(np.sum(f_el * n, 1, keepdims=True))
        vt = vel - np.sum(vel * n, 1, keepdims=True) * n
        off = points - self.anchor
        st = off - np.sum(off * n, 1, keepdims=True) * n
        trial = -cfg.tangential_damping * area[:, None] * vt - limit / cfg.stick_distance * st
        mag = np.linalg.norm(trial, axis=1, keepdims=True)
        f_el = f_el + trial * np.minimum(1.0, limit / np.maximum(mag, 1e-300))
        elastic = (depth > 0.0) & (depth < zm)
        f = np.where(elastic[:, None], f_el, plastic)
        # state update (gmloco.contact.reference.advance_stick_anchors, then z_max)
        ln = np.linalg.norm(st, axis=1, keepdims=True)
        slid = np.where(ln > cfg.stick_distance, points - st * cfg.stick_distance / np.maximum(ln, 1e-300), self.anchor)
        new = np.where((depth >= zm)[:, None], points, slid)
        self.anchor = np.where((depth > 0.0)[:, None], new, self.anchor)
        self.zmax = np.where(depth > 0.0, np.maximum(zm, depth), 0.0)  # an emerged cell forgets its crater
        return f, depth
