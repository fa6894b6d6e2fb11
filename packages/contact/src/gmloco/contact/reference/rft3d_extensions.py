# SPDX-License-Identifier: Apache-2.0
"""Float64 reference of the terms beyond 3D-RFT (``RftExtensionsCfg``) and a stateful replay of one foot.

Independent of the Warp kernels (:mod:`gmloco.contact.kernels_rft3d_ext`): the tests compare the two term by term,
and the calibration fitter drives :func:`replay_foot_forces` with recorded foot kinematics.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from gmloco.contact.colliders import ColliderPoints
from gmloco.contact.config import ContactRFT3DCfg, RftExtensionsCfg
from gmloco.contact.materials import MaterialCfg
from gmloco.contact.reference.rft3d import (
    advance_stick_anchors,
    rft3d_forces,
    rft3d_unloading_forces,
)

__all__ = [
    "ExtState",
    "advance_erosion",
    "advance_ext_state",
    "erosion_factor",
    "ext_depth_law",
    "ext_vertical_forces",
    "loosening_shift",
    "rate_drag_forces",
    "replay_foot_forces",
    "rft3d_extended_forces",
]


def ext_depth_law(depth: np.ndarray, ext: RftExtensionsCfg) -> np.ndarray:
    """Return the depth law d_ref (d / d_ref)^n, then d_s tanh(. / d_s), for d > 0 (d itself elsewhere) [m]."""
    d = np.asarray(depth, dtype=np.float64)
    out = d.copy()
    pos = d > 0.0
    if ext.depth_exponent != 1.0:
        out[pos] = ext.depth_ref * (d[pos] / ext.depth_ref) ** ext.depth_exponent
    if ext.depth_saturation > 0.0:
        out[pos] = ext.depth_saturation * np.tanh(out[pos] / ext.depth_saturation)
    return out


def ext_vertical_forces(
    normals: np.ndarray,
    velocities: np.ndarray,
    vel_prev: np.ndarray,
    depth: np.ndarray,
    areas: np.ndarray,
    rho_c: float,
    ext: RftExtensionsCfg,
    g: float,
) -> np.ndarray:
    """Return the overburden + added-mass vertical force of each element [N], [N].

    Submerged (d > 0) downward-facing (n_z < 0) elements only, with the grain mass per depth m' = rho_c |n_z| dS:
    overburden -c_ob m' g d while rising (v_z > 0); added mass c_am m' (v_z^2 - d a_z) while penetrating (v_z < 0),
    a_z = (v_z - v_z,prev) / dt.
    """
    n_z, v_z = np.asarray(normals)[:, 2], np.asarray(velocities)[:, 2]
    column = rho_c * np.maximum(-n_z, 0.0) * np.asarray(areas)
    on = (depth > 0.0) & (n_z < 0.0)
    f = np.zeros(len(n_z))
    if ext.overburden > 0.0:
        f -= np.where(on & (v_z > 0.0), ext.overburden * column * g * depth, 0.0)
    if ext.added_mass > 0.0:
        a_z = (v_z - np.asarray(vel_prev)[:, 2]) / ext.dt
        f += np.where(on & (v_z < 0.0), ext.added_mass * column * (v_z**2 - depth * a_z), 0.0)
    return f


@dataclass
class ExtState:
    """Per-element memory of one foot: z_max [m], footprint, stick anchor [m], previous velocity [m/s], tau_r."""

    depth_max: np.ndarray
    """Maximum depth since touch-down (or over the footprint) [m], [N]."""
    footprint: np.ndarray
    """Where each element last reached z_max [m], [N, 3]."""
    anchor: np.ndarray
    """Stick anchors [m], [N, 3]."""
    vel_prev: np.ndarray
    """Previous step's element velocity [m/s], [N, 3]."""
    ema_tau: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """Velocity-reversal counter tau_r [-], [N]."""
    travel: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """Horizontal travel while submerged since the element entered the sand [m], [N] (``loosening_depth``), or
    the eroded share s of its support [-], [N] (``erosion_length``)."""

    @classmethod
    def zeros(cls, num_points: int) -> ExtState:
        """Return the reset state of ``num_points`` elements."""
        z3 = np.zeros((num_points, 3))
        return cls(np.zeros(num_points), z3.copy(), z3.copy(), z3.copy(), np.zeros(num_points), np.zeros(num_points))


def loosening_shift(travel: np.ndarray, ext: RftExtensionsCfg, depth: np.ndarray | None = None) -> np.ndarray:
    """Return how much shallower each element meets the sand after its horizontal travel [m], [N] (term (f)).

    With ``depth`` [m], [N], and a keep share, at most (1 - ``loosening_keep``) of each element's depth.
    """
    if ext.loosening_depth <= 0.0:
        return np.zeros_like(np.asarray(travel, dtype=np.float64))
    shift = ext.loosening_depth * (1.0 - np.exp(-np.asarray(travel, dtype=np.float64) / ext.loosening_length))
    if depth is not None and ext.loosening_keep > 0.0:
        shift = np.minimum(shift, (1.0 - ext.loosening_keep) * np.maximum(depth, 0.0))
    return shift


def erosion_factor(share: np.ndarray, ext: RftExtensionsCfg) -> np.ndarray:
    """Return the factor 1 - (1 - keep) s on each element's vertical resistive force [-], [N] (term (g); 1 off)."""
    s = np.asarray(share, dtype=np.float64)
    if ext.erosion_length <= 0.0:
        return np.ones_like(s)
    return 1.0 - (1.0 - ext.erosion_keep) * s


def advance_erosion(
    share: np.ndarray, velocities: np.ndarray, depth: np.ndarray, depth_max: np.ndarray, ext: RftExtensionsCfg
) -> np.ndarray:
    """Return the eroded share after one step [-], [N] (term (g)).

    Grown by the horizontal travel, given back by sinking past z_max (``depth_max``, before this step's update);
    0 out of the sand.
    """
    v = np.asarray(velocities, dtype=np.float64)
    grown = share + (1.0 - share) * np.minimum(np.hypot(v[:, 0], v[:, 1]) * ext.dt / ext.erosion_length, 1.0)
    restored = grown * np.exp(-np.maximum(depth - depth_max, 0.0) / ext.erosion_restore)
    return np.where(depth > 0.0, restored, 0.0)


def rate_drag_forces(
    velocities: np.ndarray, depth: np.ndarray, areas: np.ndarray, rho_c: float, ext: RftExtensionsCfg, g: float
) -> np.ndarray:
    """Return each element's rate-dependent horizontal drag -c_rd rho_c g d dS v_xy [N], [N, 2] (term (h); 0 out)."""
    v = np.asarray(velocities, dtype=np.float64)
    weight = np.where(depth > 0.0, ext.rate_drag * rho_c * g * depth * np.asarray(areas, dtype=np.float64), 0.0)
    return -weight[:, None] * v[:, :2]


def rft3d_extended_forces(
    points: np.ndarray,
    normals: np.ndarray,
    velocities: np.ndarray,
    areas: np.ndarray,
    state: ExtState,
    cfg: ContactRFT3DCfg,
    material: MaterialCfg,
    surface_z: float = 0.0,
) -> np.ndarray:
    """Return the element forces of 3D-RFT with ``cfg.extensions`` [N], [N, 3] (``at_rest`` "none" or "unloading").

    Base: plain RFT (``"none"``) or the elastic unloading branch with crater friction (``"unloading"``), both with
    the depth law; plastic unloading zeroes 0 < d < z_max - tolerance; the lateral scale multiplies F_x, F_y; the
    bearing floor raises F_z on the loading branch; the erosion factor multiplies F_z; the rate drag is added along
    x, y, the overburden and added-mass forces along z.
    """
    ext = cfg.extensions
    if cfg.at_rest not in ("none", "unloading"):
        raise ValueError(f"reference replay supports at_rest 'none' or 'unloading', not {cfg.at_rest!r}")
    if ext.loosening_depth > 0.0:  # (f): the element meets the sand that much shallower, in loading and at rest
        shift = loosening_shift(state.travel, ext, surface_z - np.asarray(points, dtype=np.float64)[:, 2])
        up = shift[:, None] * np.array([0.0, 0.0, 1.0])  # stick anchors move with the element: offsets unchanged
        points = np.asarray(points, dtype=np.float64) + up
        state = replace(state, depth_max=np.maximum(state.depth_max - shift, 0.0), anchor=state.anchor + up)
    depth = surface_z - np.asarray(points, dtype=np.float64)[:, 2]
    law = None if ext.depth_exponent == 1.0 and ext.depth_saturation == 0.0 else (lambda d: ext_depth_law(d, ext))
    mat = {"rho_c": material.rho_c, "mu_int": material.mu_int, "mu_surf": material.mu_surf}
    if cfg.at_rest == "none":
        f = rft3d_forces(points, normals, velocities, areas, **mat, surface_z=surface_z, coeffs=cfg.coeffs,
                         v_eps=cfg.v_eps, sign_fix=cfg.sign_fix, g=cfg.gravity)  # fmt: skip
        if law is not None:
            f = f * (law(depth) / np.where(depth > 0.0, depth, 1.0))[:, None]
    else:
        sticks = cfg.static_friction
        f = rft3d_unloading_forces(
            points, normals, velocities, areas, state.depth_max, **mat, ratio=cfg.unloading_ratio,
            tangential_damping=cfg.tangential_damping, damping=cfg.unloading_damping, surface_z=surface_z,
            coeffs=cfg.coeffs, v_eps=cfg.v_eps, unloading_speed=cfg.unloading_speed, impact_damped=state.ema_tau < 1.0,
            anchors=state.anchor if sticks else None, stick_distance=cfg.stick_distance if sticks else 0.0,
            depth_law=law,
        )  # fmt: skip
    if ext.plastic_unloading:
        crater = (depth > 0.0) & (depth < state.depth_max - ext.unloading_tolerance)
        f = np.where(crater[:, None], 0.0, f)
    f = f * np.array([ext.lateral_scale, ext.lateral_scale, 1.0])
    if ext.bearing > 0.0:  # (i) bearing under motion, on the loading branch of an element not withdrawing
        v = np.asarray(velocities, dtype=np.float64)
        down = rft3d_forces(points, normals, np.tile([0.0, 0.0, -1.0], (len(v), 1)), areas, **mat,
                            surface_z=surface_z, coeffs=cfg.coeffs, v_eps=cfg.v_eps, sign_fix=cfg.sign_fix,
                            g=cfg.gravity)[:, 2]  # fmt: skip
        if law is not None:
            down = down * law(depth) / np.where(depth > 0.0, depth, 1.0)
        elastic = (cfg.at_rest == "unloading") & (depth > 0.0) & (depth < state.depth_max)
        crater = (depth > 0.0) & (depth < state.depth_max - ext.unloading_tolerance) if ext.plastic_unloading else False
        on = (depth > 0.0) & (v[:, 2] <= 0.0) & ~elastic & ~np.asarray(crater)
        f[:, 2] = np.where(on, np.maximum(f[:, 2], ext.bearing * down), f[:, 2])
    if ext.erosion_length > 0.0:  # (g) support lost to horizontal travel
        f[:, 2] *= erosion_factor(state.travel, ext)
    if ext.rate_drag > 0.0:  # (h) drag growing with the sliding speed
        f[:, :2] += rate_drag_forces(velocities, depth, areas, material.rho_c, ext, cfg.gravity)
    f[:, 2] += ext_vertical_forces(normals, velocities, state.vel_prev, depth, areas, material.rho_c, ext, cfg.gravity)
    return f


def advance_ext_state(
    state: ExtState, points: np.ndarray, normals: np.ndarray, velocities: np.ndarray, cfg: ContactRFT3DCfg,
    surface_z: float = 0.0,
) -> ExtState:  # fmt: skip
    """Return the memory after one step: anchors, z_max with footprint memory, tau_r, previous velocity."""
    x = np.asarray(points, dtype=np.float64)
    depth = surface_z - x[:, 2]
    anchor = state.anchor
    if cfg.at_rest == "unloading" and cfg.static_friction:
        anchor = advance_stick_anchors(x, normals, state.anchor, state.depth_max, cfg.stick_distance, surface_z)
    radius = cfg.extensions.footprint_radius
    loading = (depth > 0.0) & (depth >= state.depth_max)
    footprint = np.where(loading[:, None], x, state.footprint) if radius > 0.0 else state.footprint
    near = np.sum((x[:, :2] - state.footprint[:, :2]) ** 2, axis=1) < radius**2
    kept = np.where(near, state.depth_max, 0.0) if radius > 0.0 else np.zeros_like(depth)
    depth_max = np.where(depth > 0.0, np.maximum(state.depth_max, depth), kept)
    reversal = np.sum(velocities * state.vel_prev, axis=1) < 0.0
    tau = np.where(reversal & (state.ema_tau < 1.0), np.minimum(1.0, state.ema_tau + cfg.ema_rate), state.ema_tau)
    tau = np.where(depth > 0.0, tau, 0.0)
    travel = state.travel if len(state.travel) == len(depth) else np.zeros_like(depth)
    if cfg.extensions.loosening_depth > 0.0:
        v = np.asarray(velocities, dtype=np.float64)
        step = np.hypot(v[:, 0], v[:, 1]) * cfg.extensions.dt
        travel = np.where(depth > 0.0, travel + step, 0.0)
    elif cfg.extensions.erosion_length > 0.0:
        travel = advance_erosion(travel, velocities, depth, state.depth_max, cfg.extensions)
    return ExtState(depth_max, footprint, anchor, np.asarray(velocities, dtype=np.float64).copy(), tau, travel)


def replay_foot_forces(
    collider: ColliderPoints,
    pos: np.ndarray,
    rot: np.ndarray,
    lin_vel: np.ndarray,
    ang_vel: np.ndarray,
    cfg: ContactRFT3DCfg,
    material: MaterialCfg,
    surface_z: float = 0.0,
) -> np.ndarray:
    """Return the total force of the sand on one foot at each recorded step [N], [T, 3], from its kinematics.

    Each step evaluates the forces from the memory, then advances it (``compute_and_update_state``).

    Args:
        collider: Foot collider points, normals and areas in the body frame.
        pos: Body-frame origin positions [m], [T, 3].
        rot: Rotation matrices body -> world, [T, 3, 3].
        lin_vel: Linear velocity of the body-frame origin [m/s], [T, 3].
        ang_vel: Angular velocity [rad/s], [T, 3].
        cfg: Contact model (``at_rest`` "none" or "unloading") with its extensions.
        material: The medium.
        surface_z: Free-surface height [m].
    """
    state = ExtState.zeros(collider.num_points)
    out = np.zeros((len(pos), 3))
    for t in range(len(pos)):
        r = collider.points @ rot[t].T
        x, n, v = pos[t] + r, collider.normals @ rot[t].T, lin_vel[t] + np.cross(ang_vel[t], r)
        out[t] = rft3d_extended_forces(x, n, v, collider.areas, state, cfg, material, surface_z).sum(0)
        state = advance_ext_state(state, x, n, v, cfg, surface_z)
    return out
