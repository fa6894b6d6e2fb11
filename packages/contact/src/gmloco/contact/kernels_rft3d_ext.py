# SPDX-License-Identifier: Apache-2.0
"""Candidate terms beyond 3D-RFT (``RftExtensionsCfg``) as Warp functions.

Depth law, lateral scale, plastic unloading, overburden, added mass, loosening and support erosion by horizontal
travel, rate-dependent horizontal drag. Each is skipped when off, so the published force is unchanged bit for bit.

Per-world values live in one array ``values[world % values.shape[0], column]`` (shared or domain-randomized, MuJoCo
Warp's batch-modulo rule); the on/off flags are by-value struct fields fixed at model build time.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import warp as wp

__all__ = [
    "EXT_COLUMNS",
    "RftExtParams",
    "ext_depth_law",
    "ext_erosion_factor",
    "ext_lateral",
    "ext_loosening_shift",
    "ext_rate_drag",
    "ext_vertical_force",
    "ext_within_crater",
    "make_ext_params",
    "rft_ext_values",
]

EXT_COLUMNS: tuple[str, ...] = (
    "depth_exponent",
    "depth_ref",
    "depth_saturation",
    "lateral_scale",
    "overburden",
    "added_mass",
    "unloading_tolerance",
)
"""``RftExtensionsCfg`` fields held per world, in the column order of ``RftExtParams.values``."""
COL_EXPONENT = wp.constant(0)
COL_REF = wp.constant(1)
COL_SAT = wp.constant(2)
COL_LATERAL = wp.constant(3)
COL_OVERBURDEN = wp.constant(4)
COL_ADDED_MASS = wp.constant(5)
COL_TOLERANCE = wp.constant(6)


@wp.struct
class RftExtParams:
    """On/off flags of the extension terms (0/1), the per-world values [W or 1, 7] and the physics step [s].

    The per-model terms (loosening, erosion, rate drag, bearing) carry their values here; ``rate_drag`` > 0 and
    ``bearing`` > 0 are their own flags.
    """

    depth_law: int
    lateral: int
    plastic_unloading: int
    overburden: int
    added_mass: int
    values: wp.array2d[float]
    dt: float
    loosening: int
    loosening_depth: float
    loosening_length: float
    loosening_keep: float
    erosion: int
    erosion_keep: float
    rate_drag: float
    bearing: float


@wp.func
def ext_depth_law(depth: float, ext: RftExtParams, w: int) -> float:
    """Return the depth of F = alpha d dS under the depth law: d_ref (d / d_ref)^n, then d_s tanh(. / d_s) [m].

    Unchanged (the same float) when the law is off; 0 for d <= 0. Strictly increasing in d for n > 0.
    """
    if ext.depth_law == 0 or depth <= 0.0:
        return depth
    row = w % ext.values.shape[0]
    d = depth
    n = ext.values[row, COL_EXPONENT]
    if n != 1.0:
        d_ref = ext.values[row, COL_REF]
        d = d_ref * wp.pow(depth / d_ref, n)
    d_s = ext.values[row, COL_SAT]
    if d_s > 0.0:
        d = d_s * wp.tanh(d / d_s)
    return d


@wp.func
def ext_lateral(force: wp.vec3, ext: RftExtParams, w: int) -> wp.vec3:
    """Return the force with its horizontal (x, y) components times the lateral scale [N] (unchanged when off)."""
    if ext.lateral == 0:
        return force
    s = ext.values[w % ext.values.shape[0], COL_LATERAL]
    return wp.vec3(s * force[0], s * force[1], force[2])


@wp.func
def ext_within_crater(depth: float, depth_max: float, ext: RftExtParams, w: int) -> bool:
    """Return whether plastic unloading zeroes the element: 0 < d < z_max - tolerance (always False when off)."""
    if ext.plastic_unloading == 0:
        return False
    return depth > 0.0 and depth < depth_max - ext.values[w % ext.values.shape[0], COL_TOLERANCE]


@wp.func
def ext_vertical_force(
    n: wp.vec3, v: wp.vec3, v_prev: wp.vec3, depth: float, area: float, rho_c: float, gravity: float,
    ext: RftExtParams, w: int,
) -> float:  # fmt: skip
    """Return the vertical overburden and added-mass force of a submerged element [N] (0 when both are off).

    Downward-facing elements only (projected area |n_z| dS, n_z < 0). Overburden (rising, v_z > 0):
    -c_ob rho_c g d |n_z| dS. Added mass (penetrating, v_z < 0): -d(m_a v_z)/dt = c_am rho_c |n_z| dS (v_z^2 - d a_z)
    with m_a = c_am rho_c |n_z| dS d, d_dot = -v_z and a_z = (v_z - v_z,prev) / dt.
    """
    f_z = 0.0
    if depth <= 0.0 or n[2] >= 0.0:
        return f_z
    row = w % ext.values.shape[0]
    column = rho_c * (-n[2]) * area  # grain mass per depth above the element [kg/m]
    if ext.overburden != 0 and v[2] > 0.0:
        f_z -= ext.values[row, COL_OVERBURDEN] * column * gravity * depth
    if ext.added_mass != 0 and v[2] < 0.0:
        a_z = (v[2] - v_prev[2]) / ext.dt
        f_z += ext.values[row, COL_ADDED_MASS] * column * (v[2] * v[2] - depth * a_z)
    return f_z


@wp.func
def ext_loosening_shift(travel: float, depth: float, ext: RftExtParams) -> float:
    """Return how much shallower an element ``depth`` [m] deep meets the sand after ``travel`` [m] sideways [m].

    d_l (1 - exp(-u / L)) (term (f), ``RftExtensionsCfg.loosening_depth``), at most (1 - keep) of the depth with a
    keep share (``loosening_keep``); 0 when off.
    """
    if ext.loosening == 0:
        return 0.0
    shift = ext.loosening_depth * (1.0 - wp.exp(-travel / ext.loosening_length))
    if ext.loosening_keep > 0.0:
        shift = wp.min(shift, (1.0 - ext.loosening_keep) * wp.max(depth, 0.0))
    return shift


@wp.func
def ext_erosion_factor(share: float, ext: RftExtParams) -> float:
    """Return the factor 1 - (1 - keep) s on an element's vertical resistive force for eroded share s [-] (term (g))."""
    return 1.0 - (1.0 - ext.erosion_keep) * share


@wp.func
def ext_rate_drag(v: wp.vec3, depth: float, area: float, rho_c: float, gravity: float, ext: RftExtParams) -> wp.vec3:
    """Return a submerged element's rate-dependent drag -c_rd rho_c g d dS (v_x, v_y, 0) [N] (term (h); 0 above)."""
    if depth <= 0.0:
        return wp.vec3(0.0)
    k = ext.rate_drag * rho_c * gravity * depth * area
    return wp.vec3(-k * v[0], -k * v[1], 0.0)


def rft_ext_values(cfg: Any) -> np.ndarray:
    """Return the per-world value row of an ``RftExtensionsCfg`` in :data:`EXT_COLUMNS` order, [1, 7]."""
    return np.array([[float(getattr(cfg, name)) for name in EXT_COLUMNS]], dtype=np.float64)


def make_ext_params(cfg: Any, values: wp.array) -> Any:  # an RftExtParams instance (Warp struct)
    """Build :class:`RftExtParams` from an ``RftExtensionsCfg`` and its per-world ``values`` array [W or 1, 7]."""
    ext = RftExtParams()
    ext.depth_law = int(cfg.depth_exponent != 1.0 or cfg.depth_saturation > 0.0)
    ext.lateral = int(cfg.lateral_scale != 1.0)
    ext.plastic_unloading = int(cfg.plastic_unloading)
    ext.overburden = int(cfg.overburden > 0.0)
    ext.added_mass = int(cfg.added_mass > 0.0)
    ext.values = values
    ext.dt = float(cfg.dt)
    ext.loosening = int(cfg.loosening_depth > 0.0)
    ext.loosening_depth = float(cfg.loosening_depth)
    ext.loosening_length = float(cfg.loosening_length)
    ext.loosening_keep = float(cfg.loosening_keep)
    ext.erosion = int(cfg.erosion_length > 0.0)
    ext.erosion_keep = float(cfg.erosion_keep)
    ext.rate_drag = float(cfg.rate_drag)
    ext.bearing = float(cfg.bearing)
    return ext
