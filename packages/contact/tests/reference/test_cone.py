# SPDX-License-Identifier: Apache-2.0
"""Cone-RFT reference against spec 3 and table 5.5."""

from __future__ import annotations

import math

import numpy as np

from gmloco.contact.reference import (
    ConeParams,
    ConeState,
    cone_flat_area,
    cone_multi_quasi_static_force,
    cone_quasi_static_force,
    cone_step,
)

DEPTHS = np.array([5, 10, 20, 30, 50]) * 1e-3
R_SINGLE = 0.206 * 0.0736 / (0.206 + 0.0736)  # l_x l_y / (l_x + l_y) = 0.05423 m
R_MULTI = 0.0515 * 0.0184 / (0.0515 + 0.0184)  # GM-Loco linspace cell: l / (n - 1), n = 5 -> 0.01356 m


def test_single_point_table() -> None:
    """F_qs(z) for the G1 sole, GM-Loco defaults: spec table 5.5 row 1 to its 2 decimals."""
    f = cone_quasi_static_force(DEPTHS, ConeParams(r_h=R_SINGLE))
    np.testing.assert_allclose(f, [199.25, 342.24, 502.21, 565.46, 650.83], atol=6e-3)


def test_multi_point_table() -> None:
    """25 points with r_h = 0.01356 m: spec table 5.5 row 2 to its 2 decimals."""
    f = cone_multi_quasi_static_force(DEPTHS, ConeParams(r_h=R_MULTI), 25)
    np.testing.assert_allclose(f, [196.18, 237.56, 304.23, 370.90, 504.23], atol=6e-3)


def test_flat_area_saturates_at_cone_depth() -> None:
    """A_flat = 0 and dF_qs/dz = sigma_cone pi r_h^2 / cos(theta) for z >= z_c = r_h tan(theta) / nu."""
    p = ConeParams(r_h=R_SINGLE)
    z_c = p.r_h * math.tan(p.theta) / p.nu
    assert cone_flat_area(z_c * 1.01, p) == 0.0
    slope = (cone_quasi_static_force(0.06, p) - cone_quasi_static_force(0.05, p)) / 0.01
    np.testing.assert_allclose(slope, p.sigma_cone * math.pi * p.r_h**2 / math.cos(p.theta), rtol=1e-9)


def test_plastic_unloading_and_drag() -> None:
    """F = 0 when z_dot <= 0 and z < z_max - eps_f; drag c_d M A_flat z_dot^2 = 0.41 N at 1 cm, 0.5 m/s."""
    p = ConeParams(r_h=R_SINGLE)
    f, state = cone_step(0.02, -0.01, np.zeros(2), ConeState(z_max=0.025), p)
    assert np.all(f == 0.0) and state.z_max == 0.025
    f_in, _ = cone_step(0.01, 0.5, np.zeros(2), ConeState(), p)
    drag = f_in[2] - cone_quasi_static_force(0.01, p)
    np.testing.assert_allclose(drag, 0.41, atol=5e-3)  # spec 5.5: M = 382.8 kg/m^3
    f_el, _ = cone_step(0.024, -0.01, np.zeros(2), ConeState(z_max=0.025), ConeParams(r_h=R_SINGLE, unloading_ratio=5))
    # elastic line: F_qs(z_max) (1 - r (z_max - z) / z_max) = F_qs(0.025) * 0.8
    np.testing.assert_allclose(f_el[2], 0.8 * cone_quasi_static_force(0.025, p), rtol=1e-12)
