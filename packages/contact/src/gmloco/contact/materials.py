# SPDX-License-Identifier: Apache-2.0
"""Granular materials: parameters, presets, domain-randomization ranges, media scaling xi and eta."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

__all__ = [
    "DR_RANGES_CODE",
    "DR_RANGES_PAPER",
    "GRAVITY",
    "MATERIAL_PRESETS",
    "MU_INT_RANGE",
    "MU_SURF_RANGE",
    "PACKING_RANGE",
    "DrRanges",
    "MaterialCfg",
    "eta",
    "f_mu",
    "validate_material_arrays",
    "xi_max",
    "xi_n",
]

GRAVITY: float = 9.81
"""Gravitational acceleration used in the media scaling xi [m/s^2] (PNAS 2023 and every implementation)."""

MU_INT_RANGE: tuple[float, float] = (0.05, 1.2)
"""Supported internal friction mu_int = tan(phi_int) [-]. Project choice: covers the paper's DR range
0.1-1.0 and the 1.07 of a published burrowing-robot sand; beyond it the cubic f(mu) is an extrapolation."""

MU_SURF_RANGE: tuple[float, float] = (0.0, 2.0)
"""Supported intruder-medium surface friction mu_surf [-] (covers the paper's DR range 0.1-1.0)."""

PACKING_RANGE: tuple[float, float] = (0.05, 1.0)
"""Supported packing fraction (or packing ratio, GM-Loco) [-]: positive and at most 1."""


def f_mu(mu_int: np.ndarray | float) -> np.ndarray | float:
    """Return the media-scaling cubic f(mu) = 894 mu^3 - 386 mu^2 + 89 mu [-] (Agarwal et al. PNAS 2023)."""
    return 894.0 * mu_int**3 - 386.0 * mu_int**2 + 89.0 * mu_int


def xi_n(rho_c: np.ndarray | float, mu_int: np.ndarray | float, g: float = GRAVITY) -> np.ndarray | float:
    """Return the 3D-RFT media scaling xi_n = rho_c g f(mu_int) [N/m^3] (PNAS 2023).

    Args:
        rho_c: Critical (bulk x packing) density [kg/m^3].
        mu_int: Internal friction coefficient [-].
        g: Gravitational acceleration [m/s^2].
    """
    return rho_c * g * f_mu(mu_int)


@dataclass(frozen=True)
class DrRanges:
    """Domain-randomization ranges of the material parameters (uniform, inclusive)."""

    bulk_density: tuple[float, float]
    """Bulk (grain) density range [kg/m^3]."""
    packing: tuple[float, float]
    """Packing ratio range [-]; rho_c = packing * bulk_density."""
    mu_int: tuple[float, float]
    """Internal friction range [-]."""
    mu_surf: tuple[float, float]
    """Surface friction range [-]."""

    @property
    def rho_c(self) -> tuple[float, float]:
        """Range of rho_c = packing * bulk_density [kg/m^3]."""
        return (self.packing[0] * self.bulk_density[0], self.packing[1] * self.bulk_density[1])


DR_RANGES_PAPER = DrRanges(bulk_density=(1000.0, 3000.0), packing=(0.5, 1.0), mu_int=(0.1, 1.0), mu_surf=(0.1, 1.0))
"""GM-Loco project-page DR table (the paper's intent); defines xi_max for eta."""

DR_RANGES_CODE = DrRanges(bulk_density=(1000.0, 3000.0), packing=(0.5, 1.0), mu_int=(0.2, 0.9), mu_surf=(0.1, 1.0))
"""GM-Loco 2026 G1 env code DR (mu_int U[0.2, 0.9] differs from the page)."""


def xi_max(dr: DrRanges = DR_RANGES_PAPER, g: float = GRAVITY) -> float:
    """Return xi at the DR range's maximum rho_c and mu_int [N/m^3] (f is increasing, so this is the max)."""
    return float(xi_n(dr.rho_c[1], dr.mu_int[1], g))


def eta(
    rho_c: np.ndarray | float,
    mu_int: np.ndarray | float,
    scale: Literal["linear", "log"] = "linear",
    dr: DrRanges = DR_RANGES_PAPER,
) -> np.ndarray:
    """Return the normalized stiffness of a material for the terrain encoder [-].

    ``"linear"`` is the paper's definition eta = xi / xi_max. Over the paper's DR range xi spans
    xi_min/xi_max = 1.7e-3 (almost three decades), and under uniform DR sampling 59 % of all
    worlds have eta < 0.1, so an encoder sees most materials squeezed near 0. ``"log"`` maps
    log(xi) affinely onto [0, 1] between xi_min and xi_max of the range and spreads them evenly
    (see README, "eta").

    Args:
        rho_c: Critical density [kg/m^3].
        mu_int: Internal friction [-].
        scale: ``"linear"`` (paper) or ``"log"``.
        dr: DR ranges that define xi_min and xi_max.
    """
    xi = np.asarray(xi_n(np.asarray(rho_c, dtype=np.float64), np.asarray(mu_int, dtype=np.float64)))
    if scale == "linear":
        return xi / xi_max(dr)
    if scale == "log":
        lo = math.log(float(xi_n(dr.rho_c[0], dr.mu_int[0])))
        hi = math.log(xi_max(dr))
        return (np.log(xi) - lo) / (hi - lo)
    raise ValueError(f"eta scale={scale!r}: expected 'linear' or 'log'")


def _check_range(name: str, values: np.ndarray, lo: float, hi: float, lo_open: bool = False) -> None:
    """Raise ValueError naming ``name`` and its valid range if any value is outside it or not finite."""
    values = np.asarray(values, dtype=np.float64)
    bad = ~np.isfinite(values) | (values <= lo if lo_open else values < lo) | (values > hi)
    if np.any(bad):
        bracket = "(" if lo_open else "["
        raise ValueError(
            f"{name}={values[bad].ravel()[:4].tolist()} is outside the supported range {bracket}{lo}, {hi}]"
        )


def validate_material_arrays(
    rho_c: np.ndarray | None = None, mu_int: np.ndarray | None = None, mu_surf: np.ndarray | None = None
) -> None:
    """Validate material arrays; raise ValueError naming the parameter and its valid range."""
    if rho_c is not None:
        _check_range("rho_c [kg/m^3]", rho_c, 0.0, math.inf, lo_open=True)
    if mu_int is not None:
        _check_range("mu_int [-]", mu_int, *MU_INT_RANGE)
    if mu_surf is not None:
        _check_range("mu_surf [-]", mu_surf, *MU_SURF_RANGE)


@dataclass(frozen=True)
class MaterialCfg:
    """A granular medium as the RFT models see it; validated at construction."""

    bulk_density: float
    """Grain (bulk material) density [kg/m^3]; must be > 0."""
    packing: float
    """Packing fraction / ratio [-] in (0.05, 1]; rho_c = packing * bulk_density (GM-Loco convention)."""
    mu_int: float
    """Internal friction coefficient tan(phi_int) [-], supported range MU_INT_RANGE."""
    mu_surf: float
    """Intruder-medium surface friction coefficient [-], supported range MU_SURF_RANGE."""

    def __post_init__(self) -> None:
        """Fail early with the offending parameter and its valid range."""
        _check_range("bulk_density [kg/m^3]", np.array(self.bulk_density), 0.0, math.inf, lo_open=True)
        _check_range("packing [-]", np.array(self.packing), *PACKING_RANGE)
        validate_material_arrays(mu_int=np.array(self.mu_int), mu_surf=np.array(self.mu_surf))

    @property
    def rho_c(self) -> float:
        """Critical density rho_c = packing * bulk_density [kg/m^3]."""
        return self.packing * self.bulk_density

    @property
    def xi(self) -> float:
        """Media scaling xi_n [N/m^3]."""
        return float(xi_n(self.rho_c, self.mu_int))


MATERIAL_PRESETS: dict[str, MaterialCfg] = {
    # GM-Loco's box-intrusion event cfg (packing 1.0 x 2700, mu_int = tan 40 deg, mu_surf 0.5) [SRC: spec 1.4].
    # Calling it "basalt" is a project choice: 2700 kg/m^3 is basalt's grain density and 40 deg a crushed-rock
    # friction angle. Static sinkage of a standing 35 kg G1: 1.5 mm per foot (spec 5.3).
    "basalt": MaterialCfg(bulk_density=2700.0, packing=1.0, mu_int=math.tan(math.radians(40.0)), mu_surf=0.5),
    # Project choice: quartz grains 2500 kg/m^3 at loose packing 0.6 -> rho_c 1500, phi_int ~31 deg (mu 0.6),
    # mid-range of typical dry sand [INFERRED, spec 1.4]; the at-rest check uses exactly this medium.
    # Static sinkage of a standing 35 kg G1: 8.2 mm per foot (spec 5.3).
    "dry_sand": MaterialCfg(bulk_density=2500.0, packing=0.6, mu_int=0.6, mu_surf=0.4),
    # Project choice: denser, damp-compacted quartz sand (packing 0.62 of 2650, phi_int 35 deg) with higher
    # sole friction; ~1.8x stiffer than dry_sand -> about 4.5 mm static sinkage of a 35 kg G1 per foot.
    "beach_sand": MaterialCfg(bulk_density=2650.0, packing=0.62, mu_int=math.tan(math.radians(35.0)), mu_surf=0.5),
    # rho_c = 638 kg/m^3 as in GM-Loco's 2D poppy-seed configs [SRC: spec 1.4]; mu_int = 0.51 is the midpoint
    # of the values that reproduce Li et al. 2013's measured zeta for loose (0.46) and close (0.56) packing
    # [DERIVED, spec 1.4]; mu_surf = 0.3 is a project choice (smooth, oily seeds).
    "poppy_seed": MaterialCfg(bulk_density=1000.0, packing=0.638, mu_int=0.51, mu_surf=0.3),
}
"""Named material presets (see the comments for source or rationale)."""
