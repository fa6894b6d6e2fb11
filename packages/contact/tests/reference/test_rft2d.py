# SPDX-License-Identifier: Apache-2.0
"""2D-RFT and Heuristic-RFT reference against spec 2 and table 5.4."""

from __future__ import annotations

import numpy as np
import pytest

from gmloco.contact.reference import heuristic_rft_forces, rft2d_alpha, rft2d_angles

Q = np.pi / 4
# (beta, gamma) -> generic, LP (N/cm^3), CP (N/cm^3) as (alpha_x, alpha_z), spec table 5.4
TABLE = [
    ((0, np.pi / 2), (0, 1.000), (0, 0.254), (0, 0.464)),
    ((0, -np.pi / 2), (0, -0.250), (0, -0.058), (0, -0.092)),
    ((0, 0), (0.136, 0.375), (0.031, 0.098), (0.065, 0.186)),
    ((Q, 0), (0.341, 0.363), (0.082, 0.084), (0.132, 0.151)),
    ((-Q, 0), (0.165, 0.049), (0.032, 0.018), (0.040, 0.037)),
    ((np.pi / 2, 0), (0.370, 0.037), (0.083, 0.004), (0.107, 0.002)),
    ((Q, np.pi / 2), (0.219, 0.564), (0.051, 0.134), (0.103, 0.245)),
    ((np.pi / 6, np.pi / 4), (0.2940, 0.7342), (0.0687, 0.1792), (0.1281, 0.3266)),
]


@pytest.mark.parametrize(("column", "coeffs"), [(1, "generic"), (2, "poppy_lp"), (3, "poppy_cp")])
def test_table_values(column: int, coeffs: str) -> None:
    """Li 2013 Fourier fit reproduces spec table 5.4 to its printed digits (3 decimals -> 5e-4)."""
    for row in TABLE:
        np.testing.assert_allclose(np.array(rft2d_alpha(*row[0], coeffs)), row[column], atol=5.1e-4)


def test_generic_normalization_and_symmetry() -> None:
    """alpha_z^gen(0, pi/2) = 1 and alpha_x(0, +-pi/2) = 0 (the sin/cos swap of GM-Loco would break this)."""
    np.testing.assert_allclose(rft2d_alpha(0.0, np.pi / 2)[1], 1.0, atol=1e-12)
    np.testing.assert_allclose([rft2d_alpha(0.0, g)[0] for g in (np.pi / 2, -np.pi / 2)], 0.0, atol=1e-12)


def test_angles_of_a_sole() -> None:
    """A flat sole pressed down has beta = 0 and gamma = +pi/2; moving up gives gamma = -pi/2."""
    beta, gamma = rft2d_angles(np.array([[0, 0, -1.0], [0, 0, -1.0]]), np.array([[0, 0, -1.0], [0, 0, 1.0]]))
    np.testing.assert_allclose(beta, 0.0, atol=1e-12)
    np.testing.assert_allclose(gamma, [np.pi / 2, -np.pi / 2], atol=1e-12)


def test_heuristic_clamp_and_coulomb_never_add_energy() -> None:
    """F_z >= 0 always and F_t . v <= 0 (the clamp keeps suction from turning friction into propulsion)."""
    rng = np.random.default_rng(5)
    n = rng.normal(size=(2000, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = rng.normal(size=(2000, 3))
    pts = np.column_stack([np.zeros((2000, 2)), rng.uniform(-0.05, 0.01, 2000)])
    f = heuristic_rft_forces(pts, n, v, np.full(2000, 1e-4), rho_c=1500.0, mu_int=0.6, mu_surf=0.5, k_f=100.0)
    assert np.all(f[:, 2] >= 0.0)
    assert np.all(np.sum(f[:, :2] * v[:, :2], 1) <= 1e-12)
    assert np.all(f[pts[:, 2] > 0.0] == 0.0)
    # Coulomb limit |F_t| <= mu F_z
    assert np.all(np.linalg.norm(f[:, :2], axis=1) <= 0.5 * f[:, 2] + 1e-9)
