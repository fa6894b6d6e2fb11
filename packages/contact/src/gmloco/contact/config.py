# SPDX-License-Identifier: Apache-2.0
"""Configurations of the contact models: typed dataclasses, every field with its SI unit."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from gmloco.contact.coefficients import Rft2dCoeffSet
from gmloco.contact.colliders import ColliderBoxCfg, g1_foot_box_cfg
from gmloco.contact.materials import GRAVITY

__all__ = [
    "AtRestMode",
    "ContactConeMultiCfg",
    "ContactConeSingleCfg",
    "ContactHeuristicRFTCfg",
    "ContactModelCfg",
    "ContactRFT3DCfg",
    "ContactRigidCfg",
    "RftExtensionsCfg",
]

AtRestMode = Literal["none", "unloading", "ema"]
"""How a model behaves when a loaded foot comes to rest (README, "At rest"):

* ``"none"``: the published model (RFT: trailing elements get zero force; cone: plastic unloading).
* ``"unloading"``: elastic unloading branch below the remembered maximum depth with impact damping (project
  default).
* ``"ema"``: Choi 2023 S16 anti-drift EMA filter on the element force (GM-Loco's optional filter).
"""


@dataclass(frozen=True)
class _AtRestCfg:
    """Shared at-rest regularization fields."""

    at_rest: AtRestMode = "unloading"
    """At-rest treatment, see :data:`AtRestMode`."""
    unloading_ratio: float = 1.0
    """Elastic unloading stiffness over the loading (secant) stiffness [-]; the force vanishes after the
    element rises by z_max / ratio. Ratios above ~1.5 make the light, weakly held G1 foot rock at the step
    rate under 200 Hz explicit coupling (README, "At rest")."""
    unloading_damping: float = 0.001
    """Kelvin-Voigt time constant of the elastic branch [s]: d_eff += damping * ratio * d_depth/dt."""
    unloading_speed: float = 0.15
    """Impact-damping speed u0 of the elastic branch [m/s]: d_eff *= 1 + d_depth/dt / u0, clamped to [0, z_max], so
    an element rising at u0 or faster gets no elastic force back. Active until the element's velocity has reversed
    twice in contact (EMA reversal counter tau_r < 1 at the default ema_rate 0.5), so it damps the recovery after
    an impact but never the step-rate chatter of a light foot; 0 turns it off (README, "At rest")."""
    tangential_damping: float = 1.0e4
    """Viscous term of the elastic branch's friction per element area, c_t in F_t = -(k s_t + c_t dS v_t) capped
    at mu F_n [N s/m^3] (3D-RFT only; 150 N s/m for the G1 sole)."""
    ema_rate: float = 0.5
    """EMA rigidity increment per velocity reversal c_r = 100 dt [-] (0.5 at 200 Hz, Choi 2023 S16)."""


@dataclass(frozen=True)
class RftExtensionsCfg:
    """Candidate terms beyond 3D-RFT (Agarwal, Goldman & Kamrin, PNAS 2023); every default is the published 3D-RFT.

    Each term is off at its neutral value and then leaves the force bit for bit unchanged (the kernels skip it).
    The per-world values (all fields but ``footprint_radius``, the loosening, erosion and rate-drag terms and ``dt``)
    can be domain-randomized through ``ContactRFT3D.set_extensions``. Reference:
    :mod:`gmloco.contact.reference.rft3d_extensions`.
    """

    depth_exponent: float = 1.0
    """(a) Depth law exponent n: the depth in F = alpha d dS becomes d_ref (d / d_ref)^n [-]; 1 = linear (off)."""
    depth_ref: float = 0.05
    """(a) Reference depth d_ref at which the power law equals the linear law [m]."""
    depth_saturation: float = 0.0
    """(a) Saturation depth d_s: the (power-law) depth becomes d_s tanh(d / d_s) [m]; 0 = no saturation (off)."""
    lateral_scale: float = 1.0
    """(b) Factor on the horizontal (x, y) components of each element's resistive force [-]; 1 = off."""
    plastic_unloading: bool = False
    """(c) Plastic unloading: inside its crater (0 < d < z_max - unloading_tolerance) an element carries no force
    until it re-reaches its maximum depth z_max (replaces the elastic branch of ``at_rest="unloading"``)."""
    unloading_tolerance: float = 1.0e-4
    """(c) Depth band below z_max still on the loading branch [m] (as the cone model's eps_f)."""
    footprint_radius: float = 0.0
    """(c) Footprint memory: after lift-off an element keeps z_max while its horizontal distance from where it last
    reached z_max is below this radius [m], so stepping back into the footprint meets no sand above its bottom
    (with ``plastic_unloading``); 0 = z_max is forgotten out of contact (off)."""
    overburden: float = 0.0
    """(d) Overburden / suction at lift-off: a rising (v_z > 0), submerged, downward-facing element is pulled down by
    c_ob rho_c g d |n_z| dS [-], the weight of the grain column above it times c_ob; 0 = off."""
    added_mass: float = 0.0
    """(e) Added mass of the moving grains: a penetrating (v_z < 0), submerged, downward-facing element gets
    F_z = c_am rho_c |n_z| dS (v_z^2 - d a_z), i.e. -d(m_a v_z)/dt with m_a = c_am rho_c |n_z| dS d
    (Katsuragi & Durian 2007 inertial drag) and a_z by finite difference over ``dt`` [-]; 0 = off."""
    loosening_depth: float = 0.0
    """(f) Loosening by horizontal travel: an element that has travelled u metres sideways while submerged meets the
    sand as if it were ``loosening_depth`` (1 - exp(-u / loosening_length)) [m] shallower, in loading and at rest
    alike, so support lost to a slide or a turn comes back only by sinking further (MPM sand keeps 14-29 % of its
    support at rest after a 10 cm slide, 3D-RFT all of it: ``results/sand_calibration/shear/``). Travel resets out of
    the sand. 0 = off. Not domain-randomized per world (one value per model)."""
    loosening_length: float = 0.05
    """(f) Horizontal travel over which the loosening approaches ``loosening_depth`` [m]."""
    loosening_keep: float = 0.0
    """(f) Share of an element's depth that the loosening never takes away [-]: the shift is at most
    (1 - keep) times the depth, so a slid sole keeps at least this share of its support at rest, as MPM's keeps
    14-29 % (``results/sand_calibration/shear/``); 0 = the shift alone (off)."""
    erosion_length: float = 0.0
    """(g) Support erosion by horizontal travel: a submerged element that slides loses a share of its vertical
    resistive force, s <- s + (1 - s) |v_xy| dt / L_e (about 1 - exp(-u / L_e) after u metres), and the force
    becomes (1 - (1 - ``erosion_keep``) s) F_z; sinking past its maximum depth z_max by dz gives it back,
    s <- s exp(-dz / ``erosion_restore``). Unlike (f), the sand is not met shallower, so a re-press regains the
    support within a centimetre, as MPM's re-press probes do (0.25-1.35 cm, ``results/sand_calibration/shear/``).
    Shares the per-element travel memory with (f): at most one of the two is on. Out of the sand s = 0. Length [m];
    0 = off. Not domain-randomized per world (one value per model)."""
    erosion_keep: float = 0.2
    """(g) Share of the vertical force that erosion never takes away [-] (MPM keeps 14-29 % of its support at rest
    after a 10 cm slide)."""
    erosion_restore: float = 0.005
    """(g) Depth past z_max over which an eroded element's support comes back (e-folding) [m]."""
    rate_drag: float = 0.0
    """(h) Rate-dependent horizontal drag: a submerged element moving sideways at v_xy gets -c_rd rho_c g d dS v_xy
    [N], the weight of the grain column over its area times c_rd |v_xy|, opposing the slide. 3D-RFT's resistance
    does not depend on speed; under MPM's walking soles the horizontal force grows with the sole's speed (about 40 N
    planted to 100-200 N above 1 m/s at the same depth, ``results/sand_calibration/walk_replay/``). Any face, at
    the element's depth below the free surface. [s/m]; 0 = off. Not domain-randomized per world (one value per
    model)."""
    bearing: float = 0.0
    """(i) Bearing under motion: a submerged element on the loading branch that is not withdrawing (v_z <= 0) keeps
    at least ``bearing`` times the vertical force it would meet pressed straight down at its depth, whatever its
    horizontal motion. 3D-RFT's element force turns with the velocity, so a sole that rolls or slides at 0.5-2 m/s
    loses most of its vertical support; MPM's stance sole carries the robot's weight at every sole speed
    (``results/sand_calibration/walk_replay/``, forces from the robot's momentum). [-]; 0 = off. Not
    domain-randomized per world (one value per model)."""
    dt: float = 0.005
    """Physics step of the finite-difference acceleration of ``added_mass`` and of the travel of ``loosening_depth``
    and ``erosion_length`` [s] (state update once per step)."""

    def __post_init__(self) -> None:
        """Refuse values outside each term's physical range (a message per field)."""
        checks = {
            "depth_exponent": self.depth_exponent > 0.0,
            "depth_ref": self.depth_ref > 0.0,
            "depth_saturation": self.depth_saturation >= 0.0,
            "lateral_scale": self.lateral_scale >= 0.0,
            "unloading_tolerance": self.unloading_tolerance >= 0.0,
            "footprint_radius": self.footprint_radius >= 0.0,
            "overburden": self.overburden >= 0.0,
            "added_mass": self.added_mass >= 0.0,
            "loosening_depth": self.loosening_depth >= 0.0,
            "loosening_length": self.loosening_length > 0.0,
            "loosening_keep": 0.0 <= self.loosening_keep < 1.0,
            "erosion_length": self.erosion_length >= 0.0,
            "erosion_keep": 0.0 <= self.erosion_keep < 1.0,
            "erosion_restore": self.erosion_restore > 0.0,
            "rate_drag": self.rate_drag >= 0.0,
            "bearing": self.bearing >= 0.0,
            "dt": self.dt > 0.0,
        }
        for name, ok in checks.items():
            value = getattr(self, name)
            if not (ok and math.isfinite(value)):
                raise ValueError(f"RftExtensionsCfg.{name}={value}: out of range (see its docstring)")
        if self.loosening_depth > 0.0 and self.erosion_length > 0.0:
            raise ValueError(
                f"RftExtensionsCfg: loosening_depth={self.loosening_depth} and erosion_length={self.erosion_length} "
                "share one travel memory; set one of them to 0"
            )

    @property
    def is_off(self) -> bool:
        """Whether every term is at its neutral value (the model is the published 3D-RFT)."""
        return self == RftExtensionsCfg(depth_ref=self.depth_ref, unloading_tolerance=self.unloading_tolerance,
                                        loosening_length=self.loosening_length, loosening_keep=self.loosening_keep,
                                        erosion_keep=self.erosion_keep, erosion_restore=self.erosion_restore,
                                        dt=self.dt)  # fmt: skip

    @property
    def stateful(self) -> bool:
        """Whether a term reads per-element memory (z_max, footprint, previous velocity)."""
        return (
            self.plastic_unloading
            or self.footprint_radius > 0.0
            or self.added_mass > 0.0
            or self.loosening_depth > 0.0
            or self.erosion_length > 0.0
        )


@dataclass(frozen=True)
class ContactRFT3DCfg(_AtRestCfg):
    """3D resistive force theory (Agarwal, Goldman & Kamrin, PNAS 2023) on a sampled foot collider."""

    collider: ColliderBoxCfg = field(default_factory=g1_foot_box_cfg)
    """Foot collider in the body frame (faces, resolution)."""
    coeffs: str | Path = "pnas"
    """3D-RFT coefficient set: ``"pnas"`` (majority transcription), ``"gmloco"``, or a .json/.npy/.npz file."""
    sign_fix: bool = False
    """Apply the reference MATLAB sign corrections to G_n and G_t (off = literal PNAS formula, as GM-Loco)."""
    v_eps: float = 1e-4
    """Speed below which the motion direction is taken as gravity's [m/s] (spec 1.5)."""
    gravity: float = GRAVITY
    """Gravitational acceleration in xi_n = rho_c g f(mu_int) [m/s^2]."""
    static_friction: bool = True
    """Static friction in the crater (``at_rest="unloading"`` only): each submerged element keeps a stick anchor
    and its elastic branch adds a tangential spring mu |F_n| s_t / stick_distance, capped with the viscous term at
    mu |F_n| (Cundall-Strack); False = viscous-capped Coulomb only, under which a standing G1 creeps
    (README, "Static friction in the crater"). The loading (plastic) branch is unchanged either way."""
    stick_distance: float = 0.002
    """Mobilization distance s0 of the static friction [m]: the tangential slip at which the stick spring reaches
    the Coulomb force mu |F_n| (project choice, README "Static friction in the crater")."""
    extensions: RftExtensionsCfg = field(default_factory=RftExtensionsCfg)
    """Candidate terms beyond 3D-RFT (depth law, lateral scale, plastic unloading, overburden, added mass); the
    default is every term off, i.e. the published model."""


@dataclass(frozen=True)
class ContactHeuristicRFTCfg(_AtRestCfg):
    """Heuristic-RFT baseline: Li 2013 2D-RFT vertical force plus Coulomb tangential (GM-Loco "2D-warp")."""

    collider: ColliderBoxCfg = field(default_factory=g1_foot_box_cfg)
    """Foot collider in the body frame (faces, resolution)."""
    coeffs: Rft2dCoeffSet = "generic"
    """2D-RFT coefficient set; ``generic`` is scaled by xi_n, the poppy-seed sets are absolute (N/cm^3)."""
    k_f: float = 100.0
    """Tangential viscous cap per element, F_t = -min(mu F_z, k_f |v_t|) [N s/m]."""
    v_eps: float = 1e-4
    """Speed below which the motion direction is taken as gravity's [m/s]."""
    gravity: float = GRAVITY
    """Gravitational acceleration in xi_n [m/s^2]."""


@dataclass(frozen=True)
class ContactConeSingleCfg(_AtRestCfg):
    """Jammed-cone RFT (Choi et al., Sci. Robotics 2023) at one point, the sole centre (GM-Loco defaults)."""

    collider: ColliderBoxCfg = field(default_factory=g1_foot_box_cfg)
    """Foot collider; only its sole (centre, hydraulic radius) is used."""
    sigma_flat: float = 5.0e6
    """Default stress per depth on the flat area [N/m^3] (per-world override via set_materials)."""
    sigma_cone: float = 4.0e5
    """Default stress per depth on the cone flank [N/m^3] (per-world override via set_materials)."""
    nu: float = 1.0
    """Recruitment rate [-]."""
    theta: float = math.radians(30.0)
    """Shear-band angle [rad]."""
    c_g: float = 1.0
    """Surrounding-mass factor [-]."""
    c_d: float = 1.0
    """Drag factor [-]."""
    packing: float = 0.6
    """Packing fraction in the added mass M = c_g phi rho nu [-]."""
    grain_density: float = 638.0
    """Grain density in the added mass [kg/m^3]."""
    eps_f: float = 1e-4
    """Plastic-unloading tolerance on the maximum depth [m]."""
    k_f: float = 10.0
    """Tangential viscous cap F_t = -min(mu_surf F_z, k_f |v_t|) [N s/m]."""
    enable_added_mass: bool = False
    """Add m_a z_ddot with m_a = M I_flat(z) and z_ddot by finite difference (GM-Loco: off)."""
    dt: float = 0.005
    """Physics step for the finite-difference z_ddot [s]."""


@dataclass(frozen=True)
class ContactConeMultiCfg(ContactConeSingleCfg):
    """Cone-RFT at every sole grid point, each with its own state and hydraulic radius r_h / n (GM-Loco)."""


@dataclass(frozen=True)
class ContactRigidCfg:
    """No granular force: the simulator's own rigid contact acts (the paper's rigid baseline)."""

    collider: ColliderBoxCfg = field(default_factory=g1_foot_box_cfg)
    """Foot collider, kept for logging depths."""


ContactModelCfg = (
    ContactRFT3DCfg | ContactHeuristicRFTCfg | ContactConeSingleCfg | ContactConeMultiCfg | ContactRigidCfg
)
"""Any contact-model configuration accepted by :func:`make_contact_model`."""
