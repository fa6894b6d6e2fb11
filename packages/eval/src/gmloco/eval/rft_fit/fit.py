# SPDX-License-Identifier: Apache-2.0
"""Least-squares fit of the 60 3D-RFT coefficients from measured generic resistive vectors G.

G = f1 n_e + f2 v_hat + f3 g_hat with f_j = sum_k c_j^k T_k(x1, x2, x3) (Agarwal, Goldman & Kamrin, PNAS 2023,
spec 1.1) is linear in the c_j^k: each sample contributes three rows, column (k, j) = T_k(x) * basis_j, with
basis = (n_e, v_hat, g_hat). An optional ridge term pulls the solution towards a prior set where the sweep
leaves directions of coefficient space unconstrained (e.g. v_hat = +-g_hat makes the three bases dependent).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "G_HAT",
    "RftFitResult",
    "fit_rft3d_coeffs",
    "generic_from_coeffs",
    "rft3d_design_matrix",
    "rft3d_invariants",
    "rft3d_monomials",
    "rft3d_nondissipative_fraction",
    "save_rft3d_coeffs",
]

G_HAT = np.array([0.0, 0.0, -1.0])
"""Gravity direction [-]."""

_POWERS = np.array(
    [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [2, 0, 0], [0, 2, 0], [0, 0, 2], [1, 1, 0], [0, 1, 1], [1, 0, 1],
     [3, 0, 0], [0, 3, 0], [0, 0, 3], [1, 2, 0], [2, 1, 0], [0, 1, 2], [0, 2, 1], [2, 0, 1], [1, 0, 2], [1, 1, 1]]
)  # fmt: skip
"""Exponents of the 20 cubic monomials in PNAS SI order (spec 1.1 step 4)."""


def rft3d_invariants(normals: np.ndarray, velocities: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return (x [N, 3], n_e [N, 3], v_hat [N, 3]) with n_e = n if n_z < 0 else -n (spec 1.1 steps 2-3).

    Args:
        normals: Outward unit normals of the leading faces, [N, 3].
        velocities: Velocities [m/s], [N, 3] (non-zero).
    """
    n = np.asarray(normals, dtype=np.float64)
    v = np.asarray(velocities, dtype=np.float64)
    v_hat = v / np.linalg.norm(v, axis=-1, keepdims=True)
    n_e = np.where(n[:, 2:3] < 0.0, n, -n)
    x = np.stack([v_hat @ G_HAT, n_e @ G_HAT, np.sum(n_e * v_hat, axis=-1)], axis=-1)
    return x, n_e, v_hat


def rft3d_monomials(x: np.ndarray) -> np.ndarray:
    """Return the 20 cubic monomials T_k(x1, x2, x3), [N, 20]."""
    return np.prod(np.asarray(x, dtype=np.float64)[:, None, :] ** _POWERS, axis=-1)


def rft3d_design_matrix(normals: np.ndarray, velocities: np.ndarray) -> np.ndarray:
    """Return A with A @ c.ravel() = G.ravel() for c of shape [20, 3] (row-major), A of shape [3N, 60]."""
    x, n_e, v_hat = rft3d_invariants(normals, velocities)
    t = rft3d_monomials(x)  # [N, 20]
    basis = np.stack([n_e, v_hat, np.broadcast_to(G_HAT, n_e.shape)], axis=-1)  # [N, 3 (xyz), 3 (j)]
    a = t[:, None, :, None] * basis[:, :, None, :]  # [N, 3, 20, 3]
    return a.reshape(3 * len(x), 60)


def generic_from_coeffs(coeffs: np.ndarray, normals: np.ndarray, velocities: np.ndarray) -> np.ndarray:
    """Return G [N, 3] of a coefficient set [20, 3] (frame-free form, no masks)."""
    return (rft3d_design_matrix(normals, velocities) @ np.asarray(coeffs).ravel()).reshape(-1, 3)


@dataclass
class RftFitResult:
    """A fitted coefficient set and its diagnostics."""

    coeffs: np.ndarray
    """Fitted c_j^k, [20, 3] (rows k, columns j)."""
    residual_rms: float
    """RMS of G_fit - G_measured over all fitted components (normal-only samples: their normal part) [-]."""
    relative_residual: float
    """|G_fit - G| / |G| over all samples (Frobenius) [-]."""
    rank: int
    """Numerical rank of the (unregularized) design matrix (60 = every coefficient constrained)."""
    num_samples: int
    """Number of (n, v, G) samples."""


def fit_rft3d_coeffs(
    normals: np.ndarray,
    velocities: np.ndarray,
    generic: np.ndarray,
    weights: np.ndarray | None = None,
    ridge: float = 0.0,
    prior: np.ndarray | None = None,
    normal_only: np.ndarray | None = None,
) -> RftFitResult:
    """Fit the 60 coefficients by (weighted, optionally ridge-regularized) linear least squares.

    Minimizes sum_s w_s |P_s (A_s c - G_s)|^2 + ridge |c - prior|^2, where P_s is the identity, or for a
    ``normal_only`` sample the projection on its normal n_s: the RFT surface-friction cap (spec 1.1 step 7)
    keeps G.n exactly but replaces G_t, so a friction-limited measurement constrains only G.n.

    Args:
        normals: Leading-face outward normals, [N, 3].
        velocities: Velocities [m/s], [N, 3].
        generic: Measured G = alpha / xi_n [-], [N, 3].
        weights: Per-sample weights, [N]; None = 1.
        ridge: Tikhonov weight towards ``prior`` [-].
        prior: Prior coefficients [20, 3]; None = zeros.
        normal_only: Samples of which only the normal component is fitted, bool [N]; None = none.
    """
    a = rft3d_design_matrix(normals, velocities)
    g = np.asarray(generic, dtype=np.float64).ravel()
    w = np.ones(len(normals)) if weights is None else np.asarray(weights, dtype=np.float64)
    c0 = np.zeros(60) if prior is None else np.asarray(prior, dtype=np.float64).ravel()
    proj = _row_projectors(np.asarray(normals, dtype=np.float64), normal_only)  # [N, 3, 3]
    a_p = np.einsum("sij,sjk->sik", proj, a.reshape(-1, 3, 60)).reshape(-1, 60)
    g_p = np.einsum("sij,sj->si", proj, g.reshape(-1, 3)).ravel()
    sw = np.repeat(np.sqrt(w), 3)
    lhs, rhs = a_p * sw[:, None], g_p * sw
    if ridge > 0.0:
        lhs = np.vstack([lhs, np.sqrt(ridge) * np.eye(60)])
        rhs = np.concatenate([rhs, np.sqrt(ridge) * c0])
    c, *_ = np.linalg.lstsq(lhs, rhs, rcond=None)
    resid = a_p @ c - g_p
    return RftFitResult(
        coeffs=c.reshape(20, 3),
        residual_rms=float(np.sqrt(np.mean(resid**2))),
        relative_residual=float(np.linalg.norm(resid) / max(np.linalg.norm(g_p), 1e-300)),
        rank=int(np.linalg.matrix_rank(a_p)),
        num_samples=len(normals),
    )


def _row_projectors(normals: np.ndarray, normal_only: np.ndarray | None) -> np.ndarray:
    """Per-sample 3x3 row maps: identity, or n n^T for normal-only samples, [N, 3, 3]."""
    eye = np.broadcast_to(np.eye(3), (len(normals), 3, 3)).copy()
    if normal_only is None:
        return eye
    mask = np.asarray(normal_only, dtype=bool)
    n = normals / np.linalg.norm(normals, axis=-1, keepdims=True)
    eye[mask] = np.einsum("si,sj->sij", n[mask], n[mask])
    return eye


def rft3d_nondissipative_fraction(coeffs: np.ndarray, num: int = 20000, seed: int = 0) -> float:
    """Return the fraction of random leading (n, v) pairs whose G pushes along the motion (G . v_hat > 0).

    Spec section 8 step 5 (dissipativity check): such an element injects energy; the PNAS majority set has 0.07 %.
    """
    rng = np.random.default_rng(seed)
    n, v = rng.normal(size=(num, 3)), rng.normal(size=(num, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    n[np.sum(n * v, axis=1) < 0] *= -1.0  # leading faces only
    g = generic_from_coeffs(coeffs, n, v)
    return float(np.mean(np.sum(g * v, axis=1) > 0.0))


def save_rft3d_coeffs(path: str | Path, coeffs: np.ndarray, meta: dict[str, Any] | None = None) -> Path:
    """Write a coefficient set as JSON ``{"coeffs": [[c1, c2, c3] x 20], "meta": ...}`` (``load_rft3d_coeffs``)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"coeffs": np.asarray(coeffs).tolist(), "meta": meta or {}}, indent=1))
    return path
