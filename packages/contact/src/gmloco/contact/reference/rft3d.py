# SPDX-License-Identifier: Apache-2.0
"""3D resistive force theory, float64 reference (Agarwal, Goldman & Kamrin, PNAS 120 e2214017120, 2023)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Literal

import numpy as np

from gmloco.contact.coefficients import RFT3D_MONOMIAL_POWERS, resolve_rft3d_coeffs
from gmloco.contact.materials import GRAVITY, xi_n

__all__ = [
    "G_HAT",
    "advance_stick_anchors",
    "foot_wrench",
    "rft3d_alpha",
    "rft3d_forces",
    "rft3d_generic",
    "rft3d_generic_angles",
    "rft3d_unloading_forces",
    "unit_velocity",
]

G_HAT = np.array([0.0, 0.0, -1.0])
"""Unit gravity direction (world z up)."""

Coeffs = str | Path | np.ndarray


def unit_velocity(velocities: np.ndarray, v_eps: float = 1e-4) -> np.ndarray:
    """Return v_hat, with v_hat := g_hat where |v| < v_eps [m/s] (spec 1.5 zero-velocity rule)."""
    v = np.asarray(velocities, dtype=np.float64)
    speed = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(speed < v_eps, G_HAT, v / np.maximum(speed, 1e-300))


def _cubic(x: np.ndarray, coeffs: np.ndarray) -> np.ndarray:
    """Evaluate f_j = sum_k c_j^k T_k(x1, x2, x3) for j = 1..3; x is [..., 3], returns [..., 3]."""
    monomials = np.prod(x[..., None, :] ** RFT3D_MONOMIAL_POWERS, axis=-1)  # [..., 20]
    return monomials @ coeffs


def rft3d_generic(
    normals: np.ndarray, velocities: np.ndarray, coeffs: Coeffs = "pnas", v_eps: float = 1e-4
) -> np.ndarray:
    """Return the dimensionless generic resistive vector G, frame-free form (spec 1.1 steps 2-6).

    G = f1 n_e + f2 v_hat + f3 g_hat with n_e = n if n_z < 0 else -n, and the invariants
    x1 = g_hat.v_hat, x2 = g_hat.n_e, x3 = n_e.v_hat. No masks are applied.

    Args:
        normals: Outward unit normals, [N, 3].
        velocities: Velocities [m/s], [N, 3] (only the direction matters).
        coeffs: Coefficient set name, file or [20, 3] array.
        v_eps: Speed below which v_hat := g_hat [m/s].
    """
    c = resolve_rft3d_coeffs(coeffs)
    n = np.asarray(normals, dtype=np.float64)
    v_hat = unit_velocity(velocities, v_eps)
    n_e = np.where(n[..., 2:3] < 0.0, n, -n)
    x = np.stack([v_hat @ G_HAT, n_e @ G_HAT, np.sum(n_e * v_hat, axis=-1)], axis=-1)
    f = _cubic(x, c)
    return f[..., 0:1] * n_e + f[..., 1:2] * v_hat + f[..., 2:3] * G_HAT


def _local_frame(n: np.ndarray, v_hat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return (e_r, e_theta) of spec 1.2: horizontal direction of v, else of n, else +x."""
    e_z = np.array([0.0, 0.0, 1.0])
    e_r = np.tile(np.array([1.0, 0.0, 0.0]), (len(n), 1))
    for vec in (n, v_hat):  # v_hat overrides n, which overrides +x
        h = vec - np.outer(vec @ e_z, e_z)
        norm = np.linalg.norm(h, axis=-1, keepdims=True)
        e_r = np.where(norm > 1e-12, h / np.maximum(norm, 1e-300), e_r)
    return e_r, np.cross(e_z, e_r)


def _beta_gamma(n: np.ndarray, v_hat: np.ndarray, e_r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return (beta, gamma) [rad] of spec 1.2: gamma from v_hat.e_r (negative moving up), four-case beta."""
    gamma = np.arccos(np.clip(np.sum(v_hat * e_r, -1), -1.0, 1.0))
    gamma = np.where(v_hat[:, 2] > 0.0, -gamma, gamma)
    a = np.arccos(np.clip(n[:, 2], -1.0, 1.0))
    n_r, n_z = np.sum(n * e_r, -1), n[:, 2]
    beta = np.where(n_r >= 0, np.where(n_z >= 0, -a, np.pi - a), np.where(n_z >= 0, a, -np.pi + a))
    return beta, gamma


def rft3d_generic_angles(
    normals: np.ndarray,
    velocities: np.ndarray,
    coeffs: Coeffs = "pnas",
    v_eps: float = 1e-4,
    compat: Literal["reference", "gmloco"] = "reference",
) -> np.ndarray:
    """Return G through the angle form (beta, gamma, psi) of the PNAS SI S7 algorithm (spec 1.2).

    ``compat="gmloco"`` reproduces the public GM-Loco warp code, which uses atan2 for psi together with
    the four-case beta and therefore mirrors the normal whenever n.e_r < 0 (spec 1.2, do not use for physics).
    """
    c = resolve_rft3d_coeffs(coeffs)
    n = np.atleast_2d(np.asarray(normals, dtype=np.float64))
    v_hat = np.atleast_2d(unit_velocity(velocities, v_eps))
    e_r, e_t = _local_frame(n, v_hat)
    e_z = np.array([0.0, 0.0, 1.0])
    beta, gamma = _beta_gamma(n, v_hat, e_r)
    h = n - np.outer(n[:, 2], e_z)
    h_r, h_t = np.sum(h * e_r, -1), np.sum(h * e_t, -1)
    if compat == "gmloco":
        psi = np.arctan2(h_t, h_r)
    else:  # atan of the ratio; the exact limit is +-pi/2 when h_r = 0 (spec 1.2 caveat)
        psi = np.where(np.abs(h_r) > 0, np.arctan(h_t / np.where(h_r == 0, 1.0, h_r)), np.sign(h_t) * np.pi / 2)
    x1 = np.sin(gamma)
    x2 = np.cos(beta)
    x3 = np.cos(psi) * np.cos(gamma) * np.sin(beta) + np.sin(gamma) * np.cos(beta)
    f = _cubic(np.stack([x1, x2, x3], -1), c)
    g_r = f[:, 0] * np.sin(beta) * np.cos(psi) + f[:, 1] * np.cos(gamma)
    g_t = f[:, 0] * np.sin(beta) * np.sin(psi)
    g_z = -f[:, 0] * np.cos(beta) - f[:, 1] * np.sin(gamma) - f[:, 2]
    return g_r[:, None] * e_r + g_t[:, None] * e_t + g_z[:, None] * e_z


def rft3d_alpha(
    generic: np.ndarray,
    normals: np.ndarray,
    xi: np.ndarray | float,
    mu_surf: np.ndarray | float,
    velocities: np.ndarray | None = None,
    sign_fix: bool = False,
) -> np.ndarray:
    """Return alpha = xi [G_n + min(1, mu |G_n| / (|G_t| + 1e-6)) G_t] [N/m^3] (PNAS surface-friction limit).

    Args:
        generic: G, [N, 3].
        normals: Unit normals, [N, 3] (either orientation: only the projection is used).
        xi: Media scaling xi_n [N/m^3], scalar or [N].
        mu_surf: Surface friction [-], scalar or [N].
        velocities: Needed only for ``sign_fix``.
        sign_fix: Apply the reference MATLAB corrections (compressive G_n, G_t opposing v).
    """
    n = np.asarray(normals, dtype=np.float64)
    g_n = np.sum(generic * n, -1, keepdims=True) * n
    g_t = generic - g_n
    if sign_fix:
        if velocities is None:
            raise ValueError("sign_fix needs velocities")
        g_n = -np.abs(np.sum(generic * n, -1, keepdims=True)) * n
        along = np.sum(g_t * unit_velocity(velocities), -1, keepdims=True) > 0.0
        g_t = np.where(along, -g_t, g_t)
    mu = np.asarray(mu_surf, dtype=np.float64)[..., None] if np.ndim(mu_surf) else mu_surf
    scale = np.minimum(
        1.0, mu * np.linalg.norm(g_n, axis=-1, keepdims=True) / (np.linalg.norm(g_t, axis=-1, keepdims=True) + 1e-6)
    )
    xi_col = np.asarray(xi, dtype=np.float64)[..., None] if np.ndim(xi) else xi
    return xi_col * (g_n + scale * g_t)


def rft3d_forces(
    points: np.ndarray,
    normals: np.ndarray,
    velocities: np.ndarray,
    areas: np.ndarray,
    *,
    rho_c: float | np.ndarray,
    mu_int: float | np.ndarray,
    mu_surf: float | np.ndarray,
    surface_z: float | np.ndarray = 0.0,
    coeffs: Coeffs = "pnas",
    v_eps: float = 1e-4,
    sign_fix: bool = False,
    g: float = GRAVITY,
) -> np.ndarray:
    """Return 3D-RFT element forces F_i = alpha_i depth_i dS_i [N], shape [N, 3].

    Masks (spec 1.1.1): depth = surface_z - p_z > 0 and leading surface n.v_hat >= 0.

    Args:
        points: Element centroids in the world frame [m], [N, 3].
        normals: Outward unit normals, [N, 3].
        velocities: Element velocities in the world frame [m/s], [N, 3].
        areas: Element areas [m^2], [N].
        rho_c: Critical density [kg/m^3].
        mu_int: Internal friction [-].
        mu_surf: Surface friction [-].
        surface_z: Local free-surface height above each element [m], scalar or [N].
        coeffs: 3D-RFT coefficient set.
        v_eps: Speed below which v_hat := g_hat [m/s].
        sign_fix: Reference-MATLAB sign corrections (off = literal PNAS formula, as GM-Loco).
        g: Gravitational acceleration [m/s^2].
    """
    n = np.asarray(normals, dtype=np.float64)
    depth = np.asarray(surface_z, dtype=np.float64) - np.asarray(points, dtype=np.float64)[:, 2]
    v_hat = unit_velocity(velocities, v_eps)
    active = (depth > 0.0) & (np.sum(n * v_hat, -1) >= 0.0)
    generic = rft3d_generic(n, velocities, coeffs, v_eps)
    alpha = rft3d_alpha(generic, n, xi_n(rho_c, mu_int, g), mu_surf, velocities, sign_fix)
    return np.where(active[:, None], alpha * (depth * np.asarray(areas, dtype=np.float64))[:, None], 0.0)


def rft3d_unloading_forces(
    points: np.ndarray,
    normals: np.ndarray,
    velocities: np.ndarray,
    areas: np.ndarray,
    depth_max: np.ndarray,
    *,
    rho_c: float,
    mu_int: float,
    mu_surf: float,
    ratio: float,
    tangential_damping: float,
    damping: float = 0.0,
    surface_z: float | np.ndarray = 0.0,
    coeffs: Coeffs = "pnas",
    v_eps: float = 1e-4,
    unloading_speed: float = 0.0,
    impact_damped: bool | np.ndarray = True,
    anchors: np.ndarray | None = None,
    stick_distance: float = 0.0,
    depth_law: Callable[[np.ndarray], np.ndarray] | None = None,
) -> np.ndarray:
    """Return 3D-RFT forces with the project's elastic unloading branch [N], shape [N, 3].

    ``depth_law`` (``RftExtensionsCfg`` term a) maps the depth of F = alpha d dS on both branches; None = linear.

    Elements deeper than their remembered maximum depth z_max (virgin loading) get plain RFT. Inside
    the crater (0 < depth < z_max) the element is on an elastic branch: the static resistance
    alpha_s = alpha(n, v_hat = g_hat) acts on an effective depth d_eff = max(0, z_max - r (z_max - d) + damping r
    d_dot) with d_dot = -v_z (times 1 - v_z / u0 where impact-damped, clamped to [0, z_max]), plus the crater
    friction F_t = T min(1, mu |F.n| / |T|), T = -(mu |F.n| / s0) s_t - c_t dS v_t, where s_t is the offset of
    the element from its stick anchor and v_t its velocity, both in the element plane (s0 = ``stick_distance``;
    without anchors or with s0 <= 0: T = -c_t dS v_t, the viscous-capped Coulomb law).
    """
    n = np.asarray(normals, dtype=np.float64)
    v = np.asarray(velocities, dtype=np.float64)
    depth = np.asarray(surface_z, dtype=np.float64) - np.asarray(points, dtype=np.float64)[:, 2]
    plastic = rft3d_forces(
        points,
        n,
        v,
        areas,
        rho_c=rho_c,
        mu_int=mu_int,
        mu_surf=mu_surf,
        surface_z=surface_z,
        coeffs=coeffs,
        v_eps=v_eps,
    )
    if depth_law is not None:  # F is linear in the depth: rescale to the law's depth
        plastic = plastic * (depth_law(depth) / np.where(depth > 0.0, depth, 1.0))[:, None]
    static_v = np.tile(G_HAT, (len(n), 1))
    alpha_s = rft3d_alpha(rft3d_generic(n, static_v, coeffs), n, xi_n(rho_c, mu_int), mu_surf)
    d_eff = np.maximum(0.0, depth_max - ratio * (depth_max - depth) - damping * ratio * v[:, 2])
    if unloading_speed > 0.0:
        d_eff = np.where(impact_damped, d_eff * (1.0 - v[:, 2] / unloading_speed), d_eff)
    d_eff = np.clip(d_eff, 0.0, depth_max)
    if depth_law is not None:
        d_eff = depth_law(d_eff)
    f_el = alpha_s * (d_eff * areas)[:, None]
    limit = mu_surf * np.abs(np.sum(f_el * n, -1, keepdims=True))
    trial = -tangential_damping * areas[:, None] * _tangential(v, n)
    if anchors is not None and stick_distance > 0.0:
        trial -= limit / stick_distance * _tangential(np.asarray(points, dtype=np.float64) - anchors, n)
    mag = np.linalg.norm(trial, axis=-1, keepdims=True)
    f_el = f_el + trial * np.minimum(1.0, limit / np.maximum(mag, 1e-300))
    elastic = (depth > 0.0) & (depth < depth_max)
    return np.where(elastic[:, None], f_el, plastic)


def _tangential(vec: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Return the components of ``vec`` in the planes normal to the unit vectors ``n``, [N, 3]."""
    return vec - np.sum(vec * n, -1, keepdims=True) * n


def advance_stick_anchors(
    points: np.ndarray,
    normals: np.ndarray,
    anchors: np.ndarray,
    depth_max: np.ndarray,
    stick_distance: float,
    surface_z: float | np.ndarray = 0.0,
) -> np.ndarray:
    """Return the stick anchors after one substep [m], [N, 3] (Cundall-Strack spring with a Coulomb slider).

    ``depth_max`` is z_max before this substep's update. Emerged elements keep their anchor (never read); an
    element at touch-down or loading (depth >= z_max: the plastic branch, whose tangential force is plain RFT) is
    re-anchored at its position; inside its crater the anchor slides after the element just enough that the
    tangential offset |s_t| <= ``stick_distance``.
    """
    x = np.asarray(points, dtype=np.float64)
    a = np.asarray(anchors, dtype=np.float64)
    depth = np.asarray(surface_z, dtype=np.float64) - x[:, 2]
    s_t = _tangential(x - a, np.asarray(normals, dtype=np.float64))
    length = np.linalg.norm(s_t, axis=-1, keepdims=True)
    slid = np.where(length > stick_distance, x - s_t * stick_distance / np.maximum(length, 1e-300), a)
    new = np.where((depth >= np.asarray(depth_max))[:, None], x, slid)
    return np.where((depth > 0.0)[:, None], new, a)


def foot_wrench(points: np.ndarray, forces: np.ndarray, ref_point: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return (sum F [N], sum (p_i - ref) x F_i [N m]) for element forces about ``ref_point``."""
    forces = np.asarray(forces, dtype=np.float64)
    return forces.sum(0), np.cross(np.asarray(points) - np.asarray(ref_point), forces).sum(0)
