# SPDX-License-Identifier: Apache-2.0
"""Materials: f(mu) and xi (spec 5.2), presets, validation messages, eta definitions."""

from __future__ import annotations

import numpy as np
import pytest

from gmloco.contact import DR_RANGES_PAPER, MATERIAL_PRESETS, MaterialCfg, eta, xi_max, xi_n
from gmloco.contact.materials import f_mu


def test_f_mu_and_xi_match_spec_table() -> None:
    """f(mu) = 894 mu^3 - 386 mu^2 + 89 mu and xi = 1500 * 9.81 * f reproduce spec table 5.2 to its digits."""
    mu = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0])
    f_table = np.array([5.934, 9.512, 16.098, 31.056, 59.750, 107.544, 179.802, 281.888, 419.166, 597.000])
    np.testing.assert_allclose(f_mu(mu), f_table, atol=5e-4)  # table rounded to 3 decimals
    xi_table = np.array([8.73e4, 1.40e5, 2.37e5, 4.57e5, 8.79e5, 1.58e6, 2.65e6, 4.15e6, 6.17e6, 8.78e6])
    np.testing.assert_allclose(xi_n(1500.0, mu), xi_table, rtol=4e-3)  # 3 significant digits


def test_f_is_increasing_over_supported_range() -> None:
    """f'(mu) = 2682 mu^2 - 772 mu + 89 has negative discriminant, so xi is monotone in mu_int."""
    assert 772.0**2 - 4 * 2682.0 * 89.0 < 0.0
    mu = np.linspace(0.05, 1.2, 1000)
    assert np.all(np.diff(f_mu(mu)) > 0.0)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"bulk_density": 0.0}, "bulk_density"),
        ({"bulk_density": -5.0}, "bulk_density"),
        ({"packing": 1.2}, "packing"),
        ({"mu_int": 0.01}, "mu_int"),
        ({"mu_int": 1.5}, "mu_int"),
        ({"mu_surf": -0.1}, "mu_surf"),
        ({"mu_int": float("nan")}, "mu_int"),
    ],
)
def test_invalid_material_names_parameter_and_range(kwargs: dict, name: str) -> None:
    """Construction fails with a message that names the parameter and its supported range."""
    base = {"bulk_density": 2000.0, "packing": 0.6, "mu_int": 0.5, "mu_surf": 0.4}
    with pytest.raises(ValueError, match=rf"{name}.*range"):
        MaterialCfg(**{**base, **kwargs})


def test_dr_range_is_supported() -> None:
    """Every corner of the paper's DR box (mu 0.1-1.0) is a valid material."""
    for bulk in DR_RANGES_PAPER.bulk_density:
        for packing in DR_RANGES_PAPER.packing:
            for mu in DR_RANGES_PAPER.mu_int:
                MaterialCfg(bulk, packing, mu, DR_RANGES_PAPER.mu_surf[1])


def test_presets_and_sinkage_table() -> None:
    """Preset rho_c values and spec 5.3 sinkage: d = W_foot / (0.8757 xi A) for the G1 sole."""
    assert MATERIAL_PRESETS["dry_sand"].rho_c == pytest.approx(1500.0)
    assert MATERIAL_PRESETS["basalt"].rho_c == pytest.approx(2700.0)
    assert MATERIAL_PRESETS["poppy_seed"].rho_c == pytest.approx(638.0)
    area = 0.206 * 0.0736
    sink = 172.0 / (0.8757 * MATERIAL_PRESETS["dry_sand"].xi * area)
    np.testing.assert_allclose(sink, 8.2e-3, atol=5e-5)  # spec 5.3: 8.2 mm at 172 N
    sink_basalt = 343.0 / (0.8757 * MATERIAL_PRESETS["basalt"].xi * area)
    np.testing.assert_allclose(sink_basalt, 2.9e-3, atol=5e-5)  # spec 5.3: 2.9 mm at 343 N


def test_eta_definitions() -> None:
    """Eta = xi / xi_max with xi_max at (rho_c 3000, mu_int 1.0); log eta maps [xi_min, xi_max] onto [0, 1]."""
    np.testing.assert_allclose(xi_max(), 3000.0 * 9.81 * 597.0)
    np.testing.assert_allclose(eta(3000.0, 1.0), 1.0)
    np.testing.assert_allclose(eta(500.0, 0.1), xi_n(500.0, 0.1) / xi_max())
    np.testing.assert_allclose(eta([500.0, 3000.0], [0.1, 1.0], "log"), [0.0, 1.0], atol=1e-12)
    rng = np.random.default_rng(0)
    rho = rng.uniform(1000, 3000, 20000) * rng.uniform(0.5, 1.0, 20000)
    mu = rng.uniform(0.1, 1.0, 20000)
    # The paper's eta crowds near zero (median ~0.06); the log scale spreads the same worlds (median ~0.57).
    assert np.median(eta(rho, mu)) < 0.1
    assert 0.4 < np.median(eta(rho, mu, "log")) < 0.7
