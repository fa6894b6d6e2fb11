# SPDX-License-Identifier: Apache-2.0
"""Material mapping: one granular medium (rho_c, mu_int, mu_surf, packing) expressed in Newton's implicit MPM.

Every MPM evaluation in gmloco builds its sand through :func:`mpm_material` and :func:`apply_mpm_material`, so a
``MaterialCfg`` means the same medium in the RFT models and in MPM. The reasoning is in
``packages/eval/README.md`` ("Material mapping"); in short:

* ``rho_c`` -> particle density ``particle_mass / (8 r^3)``. Newton's unilateral incompressibility makes a cell
  stress-bearing only once it is fully packed by particle volume, which is the critical-state density of the
  Kamrin continuum that 3D-RFT was fitted on (Agarwal, Goldman & Kamrin, PNAS 2023; Dunatunga & Kamrin, JFM 2015).
  The bed is emitted at fill fraction 1, so its bulk density is rho_c and its lithostatic pressure rho_c g z.
* ``mu_int`` -> ``mpm:friction`` = :func:`drucker_prager_friction` (mu_int). ``mu_int`` is tan(phi) of a
  Mohr-Coulomb friction angle (the presets are defined by angles); Newton's yield surface is the Drucker-Prager
  cone sqrt(J2) <= mu p + s (checked in ``rheology_solver_kernels.shear_yield_stress``: |r_T| = sqrt(J2),
  r_N = sqrt(3/2) p). The cone passes through Mohr-Coulomb's triaxial-compression corners,
  mu = 6 sin(phi) / (sqrt(3) (3 - sin(phi))) (0.717 for mu_int = 0.6). Measured (H100, 2 cm voxels, 1000
  iterations, horizontal plate pushed down / vertical plate dragged): G_z 0.95 / 0.90 / 0.99 / 0.90 for dry sand,
  poppy seed, beach sand, basalt against PNAS's 0.876; mapping mu_int directly gave 0.49-0.59
  (``results/mpm_eval/MATERIAL_MAPPING_DIAGNOSIS.md``, section 6).
* ``mu_surf`` -> the collider (intruder) Coulomb friction, ``ShapeConfig.mu`` of the intruder's shapes.
* ``packing`` -> only through rho_c = packing * bulk_density, exactly as in the RFT models; Newton has no
  separate packing input once ``critical_fraction = 0`` (no free compaction below rho_c).
* Cohesionless, rigid-plastic sand: ``yield_stress = 0``, ``tensile_yield_ratio = 0``, ``young_modulus = 1e15``
  (Newton's default, the fully inelastic limit its solver targets), no dilatancy, hardening or viscosity.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

__all__ = ["GranularMaterial", "MpmMaterialCfg", "apply_mpm_material", "drucker_prager_friction", "mpm_material"]


class GranularMaterial(Protocol):
    """What the mapping reads from a material (``gmloco.contact.MaterialCfg`` satisfies it).

    Read-only members, so frozen dataclasses such as ``MaterialCfg`` match the protocol.
    """

    @property
    def rho_c(self) -> float:
        """Critical density [kg/m^3]."""
        ...

    @property
    def mu_int(self) -> float:
        """Internal friction coefficient [-]."""
        ...

    @property
    def mu_surf(self) -> float:
        """Intruder-medium surface friction coefficient [-]."""
        ...


@dataclass(frozen=True)
class MpmMaterialCfg:
    """Newton implicit-MPM parameters of one medium (``mpm:*`` particle attributes plus collider friction)."""

    density: float
    """Particle (fully packed) density = rho_c [kg/m^3]."""
    friction: float
    """Drucker-Prager coefficient mu in sqrt(J2) <= mu p (``mpm:friction``) = ``drucker_prager_friction(mu_int)`` [-]."""
    collider_friction: float
    """Coulomb friction between intruder and sand (``ShapeConfig.mu`` of the intruder) = mu_surf [-]."""
    young_modulus: float = 1.0e15
    """Young's modulus [Pa]; 1e15 is Newton's rigid-plastic default."""
    poisson_ratio: float = 0.3
    """Poisson ratio [-] (inactive in the rigid limit)."""
    yield_pressure: float = 1.0e12
    """Compressive yield pressure cap [Pa]; effectively infinite (no crushing)."""
    tensile_yield_ratio: float = 0.0
    """Tensile over compressive yield pressure [-]; 0 = no tension (cohesionless)."""
    yield_stress: float = 0.0
    """Deviatoric yield stress at zero pressure (cohesion) [Pa]; 0 for dry sand."""
    dilatancy: float = 0.0
    """Dilatancy factor [-]; 0 = non-associated, volume-preserving flow."""
    hardening: float = 0.0
    """Plastic hardening factor [-]."""
    critical_fraction: float = 0.0
    """``SolverImplicitMPM.Config.critical_fraction`` [-]: 0 = the bed is at rho_c and never compacts freely."""

    def mpm_attributes(self) -> dict[str, float]:
        """Return the per-particle ``model.mpm.<name>`` values of this medium."""
        return {
            "young_modulus": self.young_modulus,
            "poisson_ratio": self.poisson_ratio,
            "friction": self.friction,
            "yield_pressure": self.yield_pressure,
            "tensile_yield_ratio": self.tensile_yield_ratio,
            "yield_stress": self.yield_stress,
            "dilatancy": self.dilatancy,
            "hardening": self.hardening,
            "viscosity": 0.0,
            "damping": 0.0,
        }


def mpm_material(material: GranularMaterial, **overrides: Any) -> MpmMaterialCfg:
    """Map a granular medium to Newton implicit-MPM parameters (see the module docstring).

    Args:
        material: The medium, e.g. ``gmloco.contact.MaterialCfg``; reads ``rho_c``, ``mu_int``, ``mu_surf``.
        **overrides: Fields of :class:`MpmMaterialCfg` to change (e.g. ``young_modulus`` for a compliant bed).
    """
    rho_c = float(material.rho_c)
    if not np.isfinite(rho_c) or rho_c <= 0.0:
        raise ValueError(f"rho_c={rho_c} [kg/m^3] must be positive")
    return MpmMaterialCfg(
        density=rho_c,
        friction=drucker_prager_friction(float(material.mu_int)),
        collider_friction=float(material.mu_surf),
        **overrides,
    )


def drucker_prager_friction(mu_int: float) -> float:
    """Return Newton's ``mpm:friction`` [-] for an internal friction coefficient mu_int = tan(phi).

    The Drucker-Prager cone through the Mohr-Coulomb triaxial-compression corners:
    6 sin(phi) / (sqrt(3) (3 - sin(phi))).

    Args:
        mu_int: Internal friction coefficient tan(phi) [-], >= 0.
    """
    if not np.isfinite(mu_int) or mu_int < 0.0:
        raise ValueError(f"mu_int={mu_int} must be a finite friction coefficient >= 0")
    s = float(np.sin(np.arctan(mu_int)))
    return 6.0 * s / (np.sqrt(3.0) * (3.0 - s))


def apply_mpm_material(model: Any, mat: MpmMaterialCfg, particle_ids: np.ndarray | None = None) -> None:
    """Write the medium's ``mpm:*`` attributes into a finalized Newton model (all or some particles).

    Particle masses are set at emission (:func:`gmloco.eval.mpm.bed.emit_sand_bed`); this sets the rheology.

    Args:
        model: A ``newton.Model`` built with ``SolverImplicitMPM.register_custom_attributes``.
        mat: The mapped medium.
        particle_ids: Particles to set, [n] ints; None = all.
    """
    for name, value in mat.mpm_attributes().items():
        arr = getattr(model.mpm, name)
        if particle_ids is None:
            arr.fill_(value)
        else:
            host = arr.numpy()
            host[np.asarray(particle_ids, dtype=np.int64)] = value
            arr.assign(host)
