# SPDX-License-Identifier: Apache-2.0
"""2D resistive force theory (Li, Zhang & Goldman, Science 339:1408, 2013) and the Heuristic-RFT baseline."""

from __future__ import annotations

import numpy as np

from gmloco.contact.coefficients import RFT2D_COEFFS, RFT2D_DIMENSIONAL
from gmloco.contact.materials import GRAVITY, xi_n
from gmloco.contact.reference.rft3d import _beta_gamma, _local_frame, unit_velocity

__all__ = ["heuristic_rft_forces", "rft2d_alpha", "rft2d_angles"]


def rft2d_alpha(
    beta: np.ndarray | float, gamma: np.ndarray | float, coeffs: str = "generic"
) -> tuple[np.ndarray, np.ndarray]:
    """Return (alpha_x, alpha_z) of Li et al. 2013's Fourier fit (spec 2.1).

    alpha_z = A00 + A10 cos 2b + B11 sin(2b + g) + B01 sin g + B-11 sin(-2b + g)
    alpha_x = C11 cos(2b + g) + C01 cos g + C-11 cos(-2b + g) + D10 sin 2b
    (alpha_x uses cos for the C terms and sin for D10; GM-Loco swaps them, which breaks alpha_x(0, +-pi/2) = 0.)
    Units: dimensionless for ``generic``, N/cm^3 for the poppy-seed sets. alpha_x > 0 is drag along -e_r.
    """
    a00, a10, b11, b01, bm11, c11, c01, cm11, d10 = RFT2D_COEFFS[coeffs]
    b, g = np.asarray(beta, dtype=np.float64), np.asarray(gamma, dtype=np.float64)
    alpha_z = a00 + a10 * np.cos(2 * b) + b11 * np.sin(2 * b + g) + b01 * np.sin(g) + bm11 * np.sin(-2 * b + g)
    alpha_x = c11 * np.cos(2 * b + g) + c01 * np.cos(g) + cm11 * np.cos(-2 * b + g) + d10 * np.sin(2 * b)
    return alpha_x, alpha_z


def rft2d_angles(normals: np.ndarray, velocities: np.ndarray, v_eps: float = 1e-4) -> tuple[np.ndarray, np.ndarray]:
    """Return (beta, gamma) [rad] from outward normals and velocities with the four-case beta of spec 1.2."""
    n = np.atleast_2d(np.asarray(normals, dtype=np.float64))
    v_hat = np.atleast_2d(unit_velocity(velocities, v_eps))
    e_r, _ = _local_frame(n, v_hat)
    return _beta_gamma(n, v_hat, e_r)


def heuristic_rft_forces(
    points: np.ndarray,
    normals: np.ndarray,
    velocities: np.ndarray,
    areas: np.ndarray,
    *,
    rho_c: float | np.ndarray,
    mu_int: float | np.ndarray,
    mu_surf: float | np.ndarray,
    k_f: float = 100.0,
    surface_z: float | np.ndarray = 0.0,
    coeffs: str = "generic",
    v_eps: float = 1e-4,
    g: float = GRAVITY,
) -> np.ndarray:
    """Return Heuristic-RFT element forces [N], [N, 3] (GM-Loco "2D-warp" baseline, spec 2.4).

    F_z = max(0, s alpha_z(beta, gamma) depth dS) with s = xi_n (generic set) or 1e6 (N/cm^3 sets), no
    leading-edge mask; tangential F_t = -min(mu_surf F_z, k_f |v_t|) v_t / |v_t| in the horizontal plane.
    The F_z >= 0 clamp before the friction term is the spec's fix (an unclamped suction force would make
    the friction push along v_t).
    """
    pts = np.asarray(points, dtype=np.float64)
    v = np.asarray(velocities, dtype=np.float64)
    depth = np.asarray(surface_z, dtype=np.float64) - pts[:, 2]
    beta, gamma = rft2d_angles(normals, v, v_eps)
    _, alpha_z = rft2d_alpha(beta, gamma, coeffs)
    scale = 1e6 if RFT2D_DIMENSIONAL[coeffs] else xi_n(rho_c, mu_int, g)
    f_z = np.where(depth > 0.0, np.maximum(0.0, scale * alpha_z * depth * areas), 0.0)
    v_t = v * np.array([1.0, 1.0, 0.0])
    speed_t = np.linalg.norm(v_t, axis=-1)
    mag = np.minimum(mu_surf * f_z, k_f * speed_t)
    f_t = -mag[:, None] * v_t / np.maximum(speed_t, 1e-300)[:, None]
    return f_t + f_z[:, None] * np.array([0.0, 0.0, 1.0])
