# SPDX-License-Identifier: Apache-2.0
"""3D-RFT element forces (Agarwal, Goldman & Kamrin, PNAS 120 e2214017120, 2023), frame-free form."""

from __future__ import annotations

from typing import Any

import warp as wp

from gmloco.contact.kernels_foot import read_foot_state, skip_element
from gmloco.contact.kernels_geometry import (
    TerrainData,
    element_kinematics,
    foot_point_kinematics,
    foot_wrench_block_sum,
    media_scaling,
    point_material,
    tile_block_dim,
    write_element,
)
from gmloco.contact.kernels_rft3d_ext import (
    RftExtParams,
    ext_depth_law,
    ext_erosion_factor,
    ext_lateral,
    ext_loosening_shift,
    ext_rate_drag,
    ext_vertical_force,
    ext_within_crater,
)
from gmloco.contact.kernels_state import (
    AT_REST_EMA,
    AT_REST_UNLOADING,
    AtRestParams,
    ElementState,
    advance_element_state,
    advance_travel,
    at_rest_filter,
    crater_friction,
    elastic_depth,
    point_kernel_data,
)

__all__ = [
    "FUSED_VARIANTS",
    "RFT3DCoeffs",
    "RFT3DModel",
    "eval_rft3d_foot_wrench",
    "eval_rft3d_point_forces",
    "fused_kernel",
    "rft3d_alpha",
    "rft3d_generic",
    "rft3d_model",
    "unit_velocity",
]

G_HAT = wp.constant(wp.vec3(0.0, 0.0, -1.0))

RFT3DCoeffs = wp.types.matrix(shape=(20, 3), dtype=wp.float32)
"""The 20 x 3 PNAS coefficients passed by value (kernel parameter: constant-bank operands, no loads)."""
CubicBasis = wp.types.vector(length=20, dtype=wp.float32)
"""The 20 PNAS SI monomials T_k(x1, x2, x3), in SI order."""


@wp.func
def unit_velocity(v: wp.vec3, v_eps: float) -> wp.vec3:
    """Return v / |v|, or g_hat when |v| < v_eps (spec 1.5: a foot at rest resists as if pressed down)."""
    speed = wp.length(v)
    if speed < v_eps:
        return G_HAT
    return v / speed


@wp.func
def cubic_basis(x1: float, x2: float, x3: float) -> CubicBasis:
    """Return the 20 PNAS SI monomials once, so the three fits cost 3 x 20 FMAs (not 3 x ~64 flops)."""
    x11 = x1 * x1
    x22 = x2 * x2
    x33 = x3 * x3
    return CubicBasis(
        1.0,
        x1,
        x2,
        x3,
        x11,
        x22,
        x33,
        x1 * x2,
        x2 * x3,
        x3 * x1,
        x11 * x1,
        x22 * x2,
        x33 * x3,
        x1 * x22,
        x2 * x11,
        x2 * x33,
        x3 * x22,
        x3 * x11,
        x1 * x33,
        x1 * x2 * x3,
    )


@wp.func
def rft3d_generic(n: wp.vec3, v_hat: wp.vec3, coeffs: RFT3DCoeffs) -> wp.vec3:
    """Return G = f1 n_e + f2 v_hat + f3 g_hat with n_e = n if n_z < 0 else -n (PNAS 2023, spec 1.1).

    The 20 monomials are evaluated once and f = T^T C (3 x 20 FMAs on constant-bank operands).
    """
    n_e = n
    if n[2] >= 0.0:
        n_e = -n
    x1 = wp.dot(G_HAT, v_hat)
    x2 = wp.dot(G_HAT, n_e)
    x3 = wp.dot(n_e, v_hat)
    f = wp.mul(cubic_basis(x1, x2, x3), coeffs)
    return f[0] * n_e + f[1] * v_hat + f[2] * G_HAT


@wp.func
def rft3d_alpha(g: wp.vec3, n: wp.vec3, xi: float, mu_surf: float, v_hat: wp.vec3, sign_fix: int) -> wp.vec3:
    """Return alpha = xi [G_n + min(1, mu |G_n| / (|G_t| + 1e-6)) G_t] [N/m^3] (PNAS surface-friction cone)."""
    g_dot_n = wp.dot(g, n)
    g_n = g_dot_n * n
    g_t = g - g_n
    if sign_fix != 0:  # reference MATLAB findAlpha.m corrections (spec 1.1.7)
        g_n = -wp.abs(g_dot_n) * n
        if wp.dot(g_t, v_hat) > 0.0:
            g_t = -g_t
    scale = wp.min(1.0, mu_surf * wp.length(g_n) / (wp.length(g_t) + 1.0e-6))
    return xi * (g_n + scale * g_t)


@wp.func
def rft3d_plastic_force(
    n: wp.vec3,
    v: wp.vec3,
    depth: float,
    area: float,
    xi: float,
    mu_surf: float,
    coeffs: RFT3DCoeffs,
    v_eps: float,
    sign_fix: int,
) -> wp.vec3:
    """Return F = alpha depth dS for a submerged leading element (n.v_hat >= 0), else 0 [N]."""
    v_hat = unit_velocity(v, v_eps)
    if depth <= 0.0 or wp.dot(n, v_hat) < 0.0:
        return wp.vec3(0.0)
    return rft3d_alpha(rft3d_generic(n, v_hat, coeffs), n, xi, mu_surf, v_hat, sign_fix) * (depth * area)


@wp.func
def rft3d_elastic_force(
    n: wp.vec3,
    v: wp.vec3,
    offset: wp.vec3,
    d_eff: float,
    area: float,
    xi: float,
    mu_surf: float,
    coeffs: RFT3DCoeffs,
    rest: AtRestParams,
) -> wp.vec3:
    """Return the elastic-branch force inside the crater: static alpha on d_eff plus crater friction [N].

    d_eff is the unloading line with Kelvin-Voigt and impact damping (:func:`elastic_depth`); the tangential
    part is :func:`crater_friction` (stick spring on ``offset`` = x - anchor, viscous term c_t dS v_t, Coulomb
    cap mu |F.n|; the viscous cap alone keeps the explicit coupling stable, like GM-Loco's k_f for its
    baselines, and the spring holds a static tangential load).
    """
    alpha_s = rft3d_alpha(rft3d_generic(n, G_HAT, coeffs), n, xi, mu_surf, G_HAT, 0)
    f = alpha_s * (d_eff * area)
    return f + crater_friction(f, n, v, offset, mu_surf, rest.tangential_damping * area, rest.stick_distance)


@wp.struct
class RFT3DModel:
    """The per-element ``# Model:`` data of the 3D-RFT kernels as one by-value kernel argument.

    Collider points, outward normals [body frame] and areas [m^2]; per-world rho_c [kg/m^3], mu_int, mu_surf;
    the terrain; gravity [m/s^2]; v_eps [m/s]; the MATLAB sign fix (0/1); the at-rest parameters. The
    coefficients stay a separate kernel parameter (constant-bank operands, as before).
    """

    points_b: wp.array[wp.vec3]
    normals_b: wp.array[wp.vec3]
    areas: wp.array[float]
    rho_c: wp.array[float]
    mu_int: wp.array[float]
    mu_surf: wp.array[float]
    terrain: TerrainData
    gravity: float
    v_eps: float
    sign_fix: int
    rest: AtRestParams
    ext: RftExtParams


@wp.func
def rft3d_element_force(
    kin: wp.mat33,
    depth: float,
    mat: wp.vec3,
    coeffs: RFT3DCoeffs,
    m: RFT3DModel,
    state: ElementState,
    w: int,
    f: int,
    p: int,
) -> wp.vec3:
    """Return one submerged element's force [N]: elastic branch inside its crater, else plastic RFT; EMA filter.

    ``kin`` = rows (x, n, v) of :func:`foot_point_kinematics`; ``mat`` = (rho_c, mu_int, mu_surf). The state is
    read only where a branch needs it (z_max always; tau_r and the anchor in the elastic branch; the EMA fields
    in ``"ema"`` mode).
    """
    n = kin[1]
    v = kin[2]
    rest = m.rest
    area = m.areas[p]
    xi = media_scaling(mat[0], mat[1], m.gravity)
    depth_max = state.depth_max[w, f, p]
    force = wp.vec3(0.0)
    if rest.mode == AT_REST_UNLOADING and depth > 0.0 and depth < depth_max:
        offset = wp.vec3(0.0)
        if rest.stick_distance > 0.0:
            offset = kin[0] - state.anchor[w, f, p]
        d_eff = elastic_depth(depth, depth_max, -v[2], rest, state.ema_tau[w, f, p])
        force = rft3d_elastic_force(n, v, offset, d_eff, area, xi, mat[2], coeffs, rest)
    else:
        force = rft3d_plastic_force(n, v, depth, area, xi, mat[2], coeffs, m.v_eps, m.sign_fix)
    return at_rest_filter(force, v, depth, rest, state, w, f, p, 0)


@wp.func
def rft3d_element_force_ext(
    kin: wp.mat33,
    depth: float,
    mat: wp.vec3,
    coeffs: RFT3DCoeffs,
    m: RFT3DModel,
    state: ElementState,
    w: int,
    f: int,
    p: int,
) -> wp.vec3:
    """Return :func:`rft3d_element_force` with the extension terms (:mod:`~gmloco.contact.kernels_rft3d_ext`) [N].

    Plastic unloading in place of the crater branches, the depth law on both branches' depth, the lateral scale on
    the resistive force, the bearing floor of the loading branch, the erosion factor and the rate drag, then the
    vertical overburden and added-mass forces; each skipped where its flag is off.
    Compiled only into the kernels of models with a term on (:func:`rft3d_element_kernel_func`), so the published
    model's kernels carry none of this code (registers).
    """
    n = kin[1]
    v = kin[2]
    rest = m.rest
    ext = m.ext
    area = m.areas[p]
    xi = media_scaling(mat[0], mat[1], m.gravity)
    depth_max = state.depth_max[w, f, p]
    if ext.loosening != 0:  # (f) loosening: the element meets the sand this much shallower, loading and at rest
        shift = ext_loosening_shift(state.travel[w, f, p], depth, ext)
        depth = depth - shift
        depth_max = wp.max(depth_max - shift, 0.0)
        if depth <= 0.0:
            return wp.vec3(0.0)
    force = wp.vec3(0.0)
    bearing_z = -1.0e30  # (i) no floor unless the loading branch sets one
    if ext_within_crater(depth, depth_max, ext, w):
        force = wp.vec3(0.0)  # (c) plastic unloading: no force until z_max is re-reached
    elif rest.mode == AT_REST_UNLOADING and depth > 0.0 and depth < depth_max:
        offset = wp.vec3(0.0)
        if rest.stick_distance > 0.0:
            offset = kin[0] - state.anchor[w, f, p]
        d_eff = ext_depth_law(elastic_depth(depth, depth_max, -v[2], rest, state.ema_tau[w, f, p]), ext, w)
        force = rft3d_elastic_force(n, v, offset, d_eff, area, xi, mat[2], coeffs, rest)
    else:
        d_law = ext_depth_law(depth, ext, w)  # (a) depth law
        force = rft3d_plastic_force(n, v, d_law, area, xi, mat[2], coeffs, m.v_eps, m.sign_fix)
        if ext.bearing > 0.0 and v[2] <= 0.0:  # (i) the vertical force of a straight press at this depth
            down = wp.vec3(0.0, 0.0, -1.0)
            bearing_z = ext.bearing * rft3d_plastic_force(n, down, d_law, area, xi, mat[2], coeffs, m.v_eps,
                                                          m.sign_fix)[2]  # fmt: skip
    force = ext_lateral(force, ext, w)  # (b) lateral scale
    if bearing_z > force[2]:  # (i) bearing under motion
        force = wp.vec3(force[0], force[1], bearing_z)
    if ext.erosion != 0:  # (g) support eroded by horizontal travel
        force = wp.vec3(force[0], force[1], force[2] * ext_erosion_factor(state.travel[w, f, p], ext))
    if ext.rate_drag > 0.0:  # (h) drag growing with the sliding speed
        force = force + ext_rate_drag(v, depth, area, mat[0], m.gravity, ext)
    if ext.overburden != 0 or ext.added_mass != 0:  # (d) overburden at lift-off, (e) added mass
        f_z = ext_vertical_force(n, v, state.vel_prev[w, f, p], depth, area, mat[0], m.gravity, ext, w)
        force = force + wp.vec3(0.0, 0.0, f_z)
    return at_rest_filter(force, v, depth, rest, state, w, f, p, 0)


@wp.func
def element_active(depth: float, rest: AtRestParams) -> bool:
    """Return whether an element's force needs evaluating: submerged, or any element in ``"ema"`` mode.

    An emerged element's force is exactly zero in every mode (plastic mask, elastic branch only for depth > 0,
    EMA weight 0 out of contact), so the others are skipped (no material, xi or RFT evaluation).
    """
    return depth > 0.0 or rest.mode == AT_REST_EMA


@wp.func
def rft3d_element(  # noqa: ANN202 (returns the tuple wp.vec3, float, wp.mat33; Warp infers it)
    coeffs: RFT3DCoeffs,
    m: RFT3DModel,
    state: ElementState,
    pos: wp.vec3,
    rot: wp.mat33,
    lin_vel: wp.vec3,
    ang_vel: wp.vec3,
    w: int,
    f: int,
    p: int,
):
    """Return (force [N], depth [m], kinematics rows (x, n, v)) of element [w, f, p] of a foot with finite inputs.

    The per-element body shared by the per-point and the fused kernels: kinematics, depth below the local free
    surface, and for an :func:`element_active` element the local material and :func:`rft3d_element_force`
    (else force 0). Reads the old state only.
    """
    kin, depth = element_kinematics(m.terrain, pos, rot, lin_vel, ang_vel, m.points_b[p], m.normals_b[p])
    x = kin[0]
    force = wp.vec3(0.0)
    if element_active(depth, m.rest):
        mat = point_material(m.terrain, m.rho_c, m.mu_int, m.mu_surf, w, x[0])
        force = rft3d_element_force(kin, depth, mat, coeffs, m, state, w, f, p)
    return force, depth, kin


@wp.func
def rft3d_element_ext(  # noqa: ANN202 (returns the tuple wp.vec3, float, wp.mat33; Warp infers it)
    coeffs: RFT3DCoeffs,
    m: RFT3DModel,
    state: ElementState,
    pos: wp.vec3,
    rot: wp.mat33,
    lin_vel: wp.vec3,
    ang_vel: wp.vec3,
    w: int,
    f: int,
    p: int,
):
    """Return :func:`rft3d_element` with the extension terms (:func:`rft3d_element_force_ext`)."""
    kin, depth = element_kinematics(m.terrain, pos, rot, lin_vel, ang_vel, m.points_b[p], m.normals_b[p])
    x = kin[0]
    force = wp.vec3(0.0)
    if element_active(depth, m.rest):
        mat = point_material(m.terrain, m.rho_c, m.mu_int, m.mu_surf, w, x[0])
        force = rft3d_element_force_ext(kin, depth, mat, coeffs, m, state, w, f, p)
    return force, depth, kin


def _rft3d_point_kernel(ext: bool) -> wp.Kernel:
    """Return the per-point 3D-RFT kernel, with (``ext``) or without the extension terms compiled in."""

    @wp.kernel(name="rft3d_point_force_kernel_ext" if ext else "rft3d_point_force_kernel", module="unique")
    def rft3d_point_force_kernel(
        # Model:
        coeffs: RFT3DCoeffs,
        model: RFT3DModel,
        # Data in:
        foot_pos_in: wp.array2d[wp.vec3],
        foot_mat_in: wp.array2d[wp.mat33],
        foot_lin_vel_in: wp.array2d[wp.vec3],
        foot_ang_vel_in: wp.array2d[wp.vec3],
        state_in: ElementState,
        # Data out:
        point_force_out: wp.array3d[wp.vec3],
        point_depth_out: wp.array3d[float],
        point_vel_out: wp.array3d[wp.vec3],
        nan_count_out: wp.array[int],
    ) -> None:
        """Compute one element's 3D-RFT force, depth and velocity for [world, foot, point] (reference path)."""
        w, f, p = wp.tid()
        pos, rot, lin_vel, ang_vel, finite = read_foot_state(
            foot_pos_in, foot_mat_in, foot_lin_vel_in, foot_ang_vel_in, w, f
        )
        if not finite:
            skip_element(point_force_out, point_depth_out, point_vel_out, nan_count_out, w, f, p)
            return
        if wp.static(ext):
            force, depth, kin = rft3d_element_ext(coeffs, model, state_in, pos, rot, lin_vel, ang_vel, w, f, p)
        else:
            force, depth, kin = rft3d_element(coeffs, model, state_in, pos, rot, lin_vel, ang_vel, w, f, p)
        write_element(force, depth, kin[2], point_force_out, point_depth_out, point_vel_out, w, f, p)

    return rft3d_point_force_kernel


rft3d_point_force_kernel = _rft3d_point_kernel(False)
"""Per-point kernel of the published model (extension terms off)."""
rft3d_point_force_kernel_ext = _rft3d_point_kernel(True)
"""Per-point kernel with the extension terms compiled in."""


def rft3d_model(model: Any) -> Any:  # an RFT3DModel instance (Warp struct)
    """Return the :class:`RFT3DModel` argument of a model (its arrays are views: built per launch, cheap)."""
    m = RFT3DModel()
    m.points_b, m.normals_b, m.areas = model.points_b, model.normals_b, model.areas
    m.rho_c, m.mu_int, m.mu_surf = model.rho_c, model.mu_int, model.mu_surf
    m.terrain, m.gravity, m.v_eps = model.terrain, model.cfg.gravity, model.cfg.v_eps
    m.sign_fix, m.rest = int(model.cfg.sign_fix), model.rest
    m.ext = model.ext
    return m


def eval_rft3d_point_forces(model: Any, inputs: tuple, nan_count_out: wp.array) -> None:
    """Launch :func:`rft3d_point_force_kernel` over [num_worlds, num_feet, num_points]."""
    wp.launch(
        rft3d_point_force_kernel_ext if model.ext_on else rft3d_point_force_kernel,
        dim=model.point_depth.shape,
        inputs=[model.coeffs, rft3d_model(model), *point_kernel_data(model, inputs)],
        outputs=[model.point_force, model.point_depth, model.point_vel, nan_count_out],
        device=model.device,
    )


def _rft3d_foot_wrench_kernel(
    advance: bool, points: bool, name: str, max_registers: int | None, ext: bool = False
) -> wp.Kernel:
    """Return the fused 3D-RFT kernel, compiled with (advance=True) or without the state update.

    ``points`` False leaves out the per-point outputs (``point_force`` / ``point_depth`` / ``point_vel``, 28 B of
    stores per element): the wrench and the state are the same bit for bit; for callers that read only the wrench
    (training, see ``ContactModel.point_outputs``).

    Two specializations of one source (``wp.static``): the compute-only kernel carries no state-update code. On
    sm_90 (NVRTC, block 160 for 150 points) 96 registers per thread give 4 blocks of 5 warps per SM; the state
    update would raise the step kernel to 108 (3 blocks per SM). Recomputing x and n for the update (below) and a
    96-register cap keep the step kernel at 96 registers with no spill (cuobjdump -res-usage: the same 32-byte
    stack, no local memory as the compute-only kernel), so it keeps the occupancy. Both kernels are capped at 96
    by default: on an H100 (4,096 worlds, 150 points) the uncapped compute kernel took 85.7 us against 70.4 us
    capped (``results/benchmarks``, fourth run).
    ``max_registers``: the per-thread register cap (``None``: the compiler's choice); see :data:`FUSED_VARIANTS`.
    ``ext``: compile the extension terms in (:func:`rft3d_element_ext`); without them the kernel is the published
    model's and carries none of their code. ptxas -v for sm_90 at block 160 and cap 96 (NVRTC 13.4 PTX, ptxas 13.0):
    the training kernel ``rft3d_foot_step_kernel_nopoints`` uses 94 registers and no spills without the terms (as at
    commit 446cd8e, which has no terms) and 96 registers with 16 B of spill stores with them; compile-level
    evidence, not a timing.
    """

    @wp.kernel(name=name, module="unique", enable_backward=False, cuda_max_registers=max_registers)
    def rft3d_foot_wrench_kernel(
        # Model:
        coeffs: RFT3DCoeffs,
        model: RFT3DModel,
        # Data in:
        foot_pos_in: wp.array2d[wp.vec3],
        foot_mat_in: wp.array2d[wp.mat33],
        foot_lin_vel_in: wp.array2d[wp.vec3],
        foot_ang_vel_in: wp.array2d[wp.vec3],
        foot_com_in: wp.array2d[wp.vec3],
        # Data out:
        state_out: ElementState,
        point_force_out: wp.array3d[wp.vec3],
        point_depth_out: wp.array3d[float],
        point_vel_out: wp.array3d[wp.vec3],
        wrench_out: wp.array2d[wp.spatial_vector],
        nan_count_out: wp.array[int],
    ) -> None:
        """3D-RFT element forces and their per-foot wrench in one pass: one block per foot, lanes stride over points.

        Same element outputs as :func:`rft3d_point_force_kernel` (same :func:`rft3d_element`) and the same wrench as
        :func:`foot_wrench_kernel` (float32 round-off: cubic in basis form, tile-sum order). ``state_out`` is the
        old state the forces read; with ``advance`` each element's memory is then advanced past this substep
        by :func:`advance_element_state`, as :func:`state_update_kernel` does with the same inputs (compute() +
        update_state() in one launch; without it nothing is written to it). No race:
        element p of foot [w, f] is read (force) and then written (state) by the one lane that owns it (p = lane,
        lane + block_dim, ...), and no other thread reads or writes it.
        """
        w, f, lane = wp.tid()
        pos, rot, lin_vel, ang_vel, finite = read_foot_state(
            foot_pos_in, foot_mat_in, foot_lin_vel_in, foot_ang_vel_in, w, f
        )
        com = foot_com_in[w, f]
        force_sum = wp.vec3(0.0)
        torque_sum = wp.vec3(0.0)
        for p in range(lane, model.points_b.shape[0], wp.block_dim()):
            force = wp.vec3(0.0)
            depth = 0.0
            kin = wp.mat33(0.0)
            if finite:
                if wp.static(ext):
                    force, depth, kin = rft3d_element_ext(coeffs, model, state_out, pos, rot, lin_vel, ang_vel, w, f, p)
                else:
                    force, depth, kin = rft3d_element(coeffs, model, state_out, pos, rot, lin_vel, ang_vel, w, f, p)
                if element_active(depth, model.rest):
                    force_sum += force
                    # tau_com = sum (p_i - p_com) x F_i, as foot_wrench_kernel (x = pos + R p_b)
                    torque_sum += wp.cross(kin[0] - com, force)
            else:
                wp.atomic_add(nan_count_out, 0, 1)
            if wp.static(points):
                write_element(force, depth, kin[2], point_force_out, point_depth_out, point_vel_out, w, f, p)
            if wp.static(advance):
                # x and n recomputed with the same function instead of kept live across the force evaluation
                # (registers, see above); unused for a non-finite foot (depth 0: no anchor update)
                xn = foot_point_kinematics(pos, rot, lin_vel, ang_vel, model.points_b[p], model.normals_b[p])
                if wp.static(ext):
                    advance_travel(state_out, model.rest, w, f, p, kin[2], depth)  # before z_max moves
                advance_element_state(state_out, model.rest, 0, w, f, p, xn[0], xn[1], kin[2], depth, force)
        wrench = foot_wrench_block_sum(wp.spatial_vector(force_sum, torque_sum), pos, rot, com, lane, nan_count_out)
        if lane == 0:
            wrench_out[w, f] = wrench

    return rft3d_foot_wrench_kernel


FUSED_VARIANTS: dict[str, tuple[int | None, int | None]] = {
    "default": (96, 96),
    "nocap": (None, None),
    "cap96": (96, 96),
    "cap80": (80, 80),
    "cap64": (64, 64),
}
"""Register caps (compute kernel, step kernel) of the fused 3D-RFT kernel variants, by name (``None``: no cap).

Same source, same results bit for bit (only register allocation differs); ``"default"`` (= ``"cap96"``) is what compute() and
compute_and_update_state() launch unless a model's ``fused_variant`` says otherwise (benchmarks).
"""

_FUSED_KERNELS: dict[tuple[bool, bool, int | None, bool], wp.Kernel] = {}


def fused_kernel(variant: str, advance: bool, points: bool = True, ext: bool = False) -> wp.Kernel:
    """Return the fused kernel of a variant (:data:`FUSED_VARIANTS`), built once per register cap.

    Kernels with the default variant's cap keep the plain names; others are suffixed ``_maxreg<cap>`` /
    ``_maxregnone`` (one Warp module each, compiled on first launch). ``points`` False: the kernel without the
    per-point outputs (suffix ``_nopoints``). ``ext``: with the extension terms compiled in (suffix ``_ext``).
    """
    if variant not in FUSED_VARIANTS:
        raise ValueError(f"unknown fused variant {variant!r}: {list(FUSED_VARIANTS)}")
    default_cap = FUSED_VARIANTS["default"][advance]
    cap = FUSED_VARIANTS[variant][advance]
    if (advance, points, cap, ext) not in _FUSED_KERNELS:
        name = "rft3d_foot_step_kernel" if advance else "rft3d_foot_wrench_kernel"
        if cap != default_cap:
            name += f"_maxreg{cap if cap is not None else 'none'}"
        if not points:
            name += "_nopoints"
        if ext:
            name += "_ext"
        _FUSED_KERNELS[advance, points, cap, ext] = _rft3d_foot_wrench_kernel(advance, points, name, cap, ext)
    return _FUSED_KERNELS[advance, points, cap, ext]


rft3d_foot_wrench_kernel = fused_kernel("default", False)
"""Fused compute(): element forces + per-foot wrench, state read only."""
rft3d_foot_step_kernel = fused_kernel("default", True)
"""Fused compute_and_update_state(): as :data:`rft3d_foot_wrench_kernel`, then each lane advances its elements."""


def eval_rft3d_foot_wrench(model: Any, inputs: tuple, wrench_out: wp.array, advance: bool = False) -> None:
    """Launch the fused 3D-RFT kernel over [num_worlds, num_feet] blocks of :func:`tile_block_dim` lanes.

    ``advance`` False: :data:`rft3d_foot_wrench_kernel` (compute()); True: :data:`rft3d_foot_step_kernel`, which
    also advances the element state (compute() + update_state() in one launch). ``model.fused_variant`` (default
    ``"default"``) picks the kernel variant (:func:`fused_kernel`; all give the same results bit for bit);
    ``model.point_outputs`` False launches the kernel that leaves the per-point outputs unwritten.
    """
    variant = getattr(model, "fused_variant", "default")
    kernel = fused_kernel(variant, advance, getattr(model, "point_outputs", True), model.ext_on)
    dim = (model.num_worlds, model.num_feet)
    wp.launch_tiled(
        kernel,
        dim=dim,
        inputs=[model.coeffs, rft3d_model(model), *inputs],
        outputs=[model.state, model.point_force, model.point_depth, model.point_vel, wrench_out, model.nan_count],
        block_dim=tile_block_dim(model.num_points),
        device=model.device,
    )
