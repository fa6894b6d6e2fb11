# SPDX-License-Identifier: Apache-2.0
"""ContactModel: allocation, per-world materials, and the compute / update_state / reset sequence."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import warp as wp

from gmloco.contact.colliders import ColliderPoints
from gmloco.contact.kernels_geometry import (
    TerrainData,
    eval_foot_wrench,
    eval_foot_wrench_tiled,
    eval_material_eta,
    eval_scatter_values,
)
from gmloco.contact.kernels_state import (
    AT_REST_CODES,
    AtRestParams,
    ElementState,
    eval_reset_state,
    eval_state_update,
)
from gmloco.contact.materials import MATERIAL_PRESETS, eta, validate_material_arrays
from gmloco.contact.terrain import HEIGHT_KINDS, TerrainCfg

__all__ = ["ContactModel", "make_at_rest_params", "make_terrain_data"]

DEFAULT_MATERIAL = MATERIAL_PRESETS["dry_sand"]
"""Material every world starts with until :meth:`ContactModel.set_materials` is called."""


def make_terrain_data(cfg: TerrainCfg, device: str) -> Any:  # a TerrainData instance (Warp struct)
    """Upload a :class:`TerrainCfg` into the kernels' :class:`TerrainData` struct."""
    t = TerrainData()
    t.kind = HEIGHT_KINDS[cfg.height]
    t.z0 = cfg.surface_z
    t.amplitude = wp.vec2(*cfg.amplitude)
    t.wavelength = wp.vec2(*cfg.wavelength)
    t.grid = wp.array(cfg.grid_array, dtype=float, device=device)
    t.grid_origin = wp.vec2(*cfg.grid_origin)
    t.grid_spacing = cfg.grid_spacing
    t.num_materials = len(cfg.materials)
    t.material_table = wp.array(cfg.material_table if cfg.materials else np.zeros((1, 3)), dtype=float, device=device)
    edges = np.asarray(cfg.material_x_edges, dtype=np.float64)
    t.material_edges = wp.array(edges if edges.size else np.zeros(1), dtype=float, device=device)
    t.material_blend = cfg.material_blend
    return t


def make_at_rest_params(cfg: Any) -> Any:  # an AtRestParams instance (Warp struct)
    """Collect a config's at-rest fields (defaults of ``_AtRestCfg`` where it has none) into :class:`AtRestParams`.

    The stick distance is kept only where static friction applies (3D-RFT, ``at_rest="unloading"``); 0 elsewhere.
    """
    rest = AtRestParams()
    rest.mode = AT_REST_CODES[getattr(cfg, "at_rest", "none")]
    rest.unloading_ratio = getattr(cfg, "unloading_ratio", 1.0)
    rest.unloading_damping = getattr(cfg, "unloading_damping", 0.0)
    rest.unloading_speed = getattr(cfg, "unloading_speed", 0.0)
    rest.tangential_damping = getattr(cfg, "tangential_damping", 0.0)
    rest.ema_rate = getattr(cfg, "ema_rate", 0.0)
    sticks = getattr(cfg, "static_friction", False) and rest.mode == AT_REST_CODES["unloading"]
    rest.stick_distance = float(cfg.stick_distance) if sticks else 0.0
    ext = getattr(cfg, "extensions", None)
    rest.footprint_radius = float(ext.footprint_radius) if ext is not None else 0.0
    rest.loosening_dt = float(ext.dt) if ext is not None and ext.loosening_depth > 0.0 else 0.0
    rest.erosion_rate, rest.erosion_restore = 0.0, 1.0
    if ext is not None and ext.erosion_length > 0.0:
        rest.erosion_rate, rest.erosion_restore = float(ext.dt / ext.erosion_length), float(ext.erosion_restore)
    return rest


def _is_device_array(values: Any) -> bool:
    """Whether ``values`` is a warp array or a torch tensor (written without a host round trip)."""
    return isinstance(values, wp.array) or hasattr(values, "detach")


def _as_warp(values: Any, dtype: type) -> wp.array:
    """Return a warp array as is, or a torch tensor as a 1-D warp array of ``dtype`` (float32 / int32)."""
    if isinstance(values, wp.array):
        return values
    import torch  # a tensor was passed, so torch is installed

    tensor = values.detach().reshape(-1).to(torch.float32 if dtype is float else torch.int32).contiguous()
    return wp.from_torch(tensor, dtype=wp.float32 if dtype is float else wp.int32)


def _to_numpy(values: Any) -> np.ndarray:
    """Convert numpy, torch (any device), warp or scalars to a float64 numpy array."""
    if isinstance(values, wp.array):
        return values.numpy().astype(np.float64)
    if hasattr(values, "detach"):
        return values.detach().cpu().numpy().astype(np.float64)
    return np.asarray(values, dtype=np.float64)


class ContactModel:
    """Granular foot-contact model batched over [num_worlds, num_feet, num_points] (base class).

    Attributes:
        point_depth: Element depth below the local free surface [m], wp.array3d[float] [W, F, P].
        point_force: Element force of the medium on the foot [N], wp.array3d[wp.vec3] [W, F, P].
        point_vel: Element velocity [m/s], wp.array3d[wp.vec3] [W, F, P]. point_depth / point_force / point_vel
            are written by compute() (the last call's inputs; not on the fused path with ``point_outputs`` False);
            update_state() does not rewrite them.
        force_prev: Previous substep's element force [N], [W, F, P]: kept only in ``at_rest="ema"``, the only
            mode that reads it.
        anchor: Stick anchor of each submerged element, world frame [m], [W, F, P] (3D-RFT static friction).
        footprint: Where each element last reached its maximum depth, world frame [m], [W, F, P] (3D-RFT footprint
            memory, ``RftExtensionsCfg.footprint_radius``).
        nan_count: Count of non-finite element inputs seen by compute() (one per element per call), [1].
        eta: Normalized stiffness xi / xi_max of each world's material (paper definition) [-], [W].
        eta_log: Log-scaled normalized stiffness (materials.eta scale="log") [-], [W].
    """

    is_rigid: bool = False
    fused: bool = True
    """compute() path. True (default): the model's fused points + wrench pass where it has one (3D-RFT), else its
    per-point pass + a tiled per-foot sum (one block per foot). False: per-point pass + one-thread-per-foot sum,
    kept as the parity oracle of the tile sums and for benchmarks; both paths evaluate each element with the
    same functions (same results to float32 round-off in the sum order). update_state() is one path;
    compute_and_update_state() is one launch on the fused 3D-RFT path, else compute() then update_state()."""
    point_outputs: bool = True
    """Whether compute() writes ``point_force`` / ``point_depth`` / ``point_vel`` (per-element diagnostics).
    False (training: only the wrench is read) skips those stores on the fused 3D-RFT path; the wrench and the
    state are unchanged bit for bit. Other paths need the per-point arrays and always write them."""
    _vertical_only: int = 0
    _eval_points: Callable[[Any, tuple, wp.array], None]
    _eval_fused: Callable[..., None] | None = None
    """Fused compute(): ``(model, inputs, wrench_out, advance=False)``; ``advance=True`` also advances the state."""

    def __init__(
        self,
        cfg: Any,
        num_worlds: int,
        num_feet: int,
        device: str,
        terrain: TerrainCfg | None,
        collider: ColliderPoints,
    ) -> None:
        """Allocate every array once (graph capture freezes pointers: never reallocate)."""
        self.cfg = cfg
        self.num_worlds, self.num_feet, self.num_points = num_worlds, num_feet, collider.num_points
        self.device = device
        self.collider = collider
        self.rest = make_at_rest_params(cfg)
        self.at_rest_code = self.rest.mode
        self.terrain_cfg = terrain or TerrainCfg()
        self.terrain = make_terrain_data(self.terrain_cfg, device)
        self.points_b = wp.array(collider.points, dtype=wp.vec3, device=device)
        self.normals_b = wp.array(collider.normals, dtype=wp.vec3, device=device)
        self.areas = wp.array(collider.areas, dtype=float, device=device)
        m = DEFAULT_MATERIAL
        self.rho_c = wp.full(num_worlds, m.rho_c, dtype=float, device=device)
        self.mu_int = wp.full(num_worlds, m.mu_int, dtype=float, device=device)
        self.mu_surf = wp.full(num_worlds, m.mu_surf, dtype=float, device=device)
        self.eta = wp.full(num_worlds, float(eta(m.rho_c, m.mu_int)), dtype=float, device=device)
        self.eta_log = wp.full(num_worlds, float(eta(m.rho_c, m.mu_int, "log")), dtype=float, device=device)
        shape = (num_worlds, num_feet, collider.num_points)
        self.point_depth = wp.zeros(shape, dtype=float, device=device)
        self.point_force = wp.zeros(shape, dtype=wp.vec3, device=device)
        self.point_vel = wp.zeros(shape, dtype=wp.vec3, device=device)
        self.depth_max = wp.zeros(shape, dtype=float, device=device)
        self.ema_tau = wp.zeros(shape, dtype=float, device=device)
        self.force_prev = wp.zeros(shape, dtype=wp.vec3, device=device)
        self.vel_prev = wp.zeros(shape, dtype=wp.vec3, device=device)
        self.anchor = wp.zeros(shape, dtype=wp.vec3, device=device)
        self.footprint = wp.zeros(shape, dtype=wp.vec3, device=device)
        self.travel = wp.zeros(shape, dtype=float, device=device)
        self.state = ElementState()
        """The memory above as one kernel argument (the same arrays: views, never reallocated)."""
        self.state.depth_max, self.state.ema_tau, self.state.anchor = self.depth_max, self.ema_tau, self.anchor
        self.state.force_prev, self.state.vel_prev = self.force_prev, self.vel_prev
        self.state.footprint, self.state.travel = self.footprint, self.travel
        self.nan_count = wp.zeros(1, dtype=int, device=device)
        self._scratch_count = wp.zeros(1, dtype=int, device=device)

    @property
    def is_stateful(self) -> bool:
        """Whether update_state() changes what compute() returns (False: it may be skipped)."""
        return not self.is_rigid and (self.at_rest_code != 0 or self._always_stateful)

    _always_stateful: bool = False

    # -- materials -------------------------------------------------------------------------------------------

    def _world_ids(self, env_ids: Any, count: int) -> wp.array:
        """Return env_ids as a wp int array (all worlds when None), checking the value count."""
        ids = np.arange(self.num_worlds) if env_ids is None else _to_numpy(env_ids).astype(np.int64).ravel()
        if count != len(ids):
            raise ValueError(f"set_materials: got {count} values for {len(ids)} worlds")
        if len(ids) and (ids.min() < 0 or ids.max() >= self.num_worlds):
            raise ValueError(f"env_ids must lie in [0, {self.num_worlds - 1}]")
        return wp.array(ids.astype(np.int32), dtype=int, device=self.device)

    def set_materials(
        self, rho_c: Any = None, mu_int: Any = None, mu_surf: Any = None, env_ids: Any = None, **extra: Any
    ) -> None:
        """Set per-world materials in place and recompute eta / eta_log of those worlds; None leaves one unchanged.

        The one writer of the per-world material arrays. Host values (numpy, lists, scalars) are range-checked;
        torch tensors and warp arrays (all of them, ``env_ids`` too) stay on the device, unchecked and without a
        host round trip (the caller draws them from checked ranges, as ``gmloco.train``'s ``MaterialWriter``).

        Args:
            rho_c: Critical density [kg/m^3], [num_worlds] or [len(env_ids)] (numpy, torch, warp or scalar).
            mu_int: Internal friction [-], same shape.
            mu_surf: Surface friction [-], same shape.
            env_ids: Worlds to update; None = all.
            **extra: Model-specific per-world parameters (cone: sigma_flat, sigma_cone [N/m^3]).
        """
        given = {
            k: v for k, v in {"rho_c": rho_c, "mu_int": mu_int, "mu_surf": mu_surf, **extra}.items() if v is not None
        }
        if not given:
            return
        on_device = all(_is_device_array(v) for v in given.values())
        ids, arrays = self._device_inputs(env_ids, given) if on_device else self._host_inputs(env_ids, given)
        for name, values in arrays.items():
            eval_scatter_values(ids, values, getattr(self, name))
        if "rho_c" in arrays or "mu_int" in arrays:
            eval_material_eta(self, ids, self.eta, self.eta_log)

    def _host_inputs(self, env_ids: Any, given: dict[str, Any]) -> tuple[wp.array, dict[str, wp.array]]:
        """Range-check host values and upload them with their world ids."""
        count = len(np.atleast_1d(_to_numpy(next(iter(given.values())))))
        ids = self._world_ids(env_ids, count)
        arrays = {k: np.broadcast_to(np.atleast_1d(_to_numpy(v)), (count,)).copy() for k, v in given.items()}
        validate_material_arrays(arrays.get("rho_c"), arrays.get("mu_int"), arrays.get("mu_surf"))
        self._validate_extra(arrays)
        return ids, {k: wp.array(v, dtype=float, device=self.device) for k, v in arrays.items()}

    def _device_inputs(self, env_ids: Any, given: dict[str, Any]) -> tuple[wp.array, dict[str, wp.array]]:
        """Wrap device values and their world ids as warp arrays (zero-copy where already float32 / int32)."""
        self._validate_extra({k: np.ones(1) for k in given})  # names only: the values stay on the device
        arrays = {k: _as_warp(v, float) for k, v in given.items()}
        count = next(iter(arrays.values())).shape[0]
        ids = wp.array(np.arange(self.num_worlds, dtype=np.int32), device=self.device)
        if env_ids is not None:
            ids = _as_warp(env_ids, int)
        if any(a.shape[0] != ids.shape[0] for a in arrays.values()) or count != ids.shape[0]:
            raise ValueError(f"set_materials: got {count} values for {ids.shape[0]} worlds")
        return ids, arrays

    def _validate_extra(self, arrays: dict[str, np.ndarray]) -> None:
        """Reject parameters this model does not have (subclasses add theirs)."""
        unknown = set(arrays) - {"rho_c", "mu_int", "mu_surf"}
        if unknown:
            raise ValueError(f"{type(self).__name__}.set_materials: unknown parameters {sorted(unknown)}")

    # -- simulation ------------------------------------------------------------------------------------------

    def compute(
        self,
        foot_pos_w: wp.array,
        foot_mat_w: wp.array,
        foot_lin_vel_w: wp.array,
        foot_ang_vel_w: wp.array,
        foot_com_w: wp.array,
        wrench_out: wp.array,
    ) -> None:
        """Write each foot's wrench (force, torque about its CoM; world frame) without touching model state.

        Args:
            foot_pos_w: Body-frame origin positions [m], wp.array2d[wp.vec3] [W, F].
            foot_mat_w: Rotation matrices body -> world, wp.array2d[wp.mat33] [W, F].
            foot_lin_vel_w: Linear velocity of the body-frame origin [m/s], [W, F].
            foot_ang_vel_w: Angular velocity [rad/s], [W, F].
            foot_com_w: Body centre of mass [m], [W, F].
            wrench_out: Output, wp.array2d[wp.spatial_vector] [W, F], MuJoCo ``xfrc_applied`` layout.
        """
        inputs = (foot_pos_w, foot_mat_w, foot_lin_vel_w, foot_ang_vel_w, foot_com_w)
        if self.fused and self._eval_fused is not None:
            # 1+2. one block per foot: element forces, depths, velocities and the block's tile sum, one launch
            self._eval_fused(self, inputs, wrench_out)
            return
        # 1. element forces, depths and velocities from the kinematics and the (read-only) state
        self._eval_points(self, inputs, self.nan_count)
        # 2. per-foot sum of forces and of moments about the CoM, fixed order (tiled: one block per foot)
        (eval_foot_wrench_tiled if self.fused else eval_foot_wrench)(self, inputs, wrench_out)

    def update_state(
        self,
        foot_pos_w: wp.array,
        foot_mat_w: wp.array,
        foot_lin_vel_w: wp.array,
        foot_ang_vel_w: wp.array,
        foot_com_w: wp.array,
    ) -> None:
        """Advance the memory once per physics substep, with the kinematics compute() used in that substep.

        After ``mj_step`` MuJoCo's ``xpos``/``xmat``/``cvel`` still hold the pre-integration kinematics that the
        passive callback saw, so reading them after the step gives exactly those inputs.

        Contract: the new state depends only on these inputs and the current state, never on what compute()
        left in ``point_*`` (compute() may run any number of times per substep, e.g. again in ``sim.forward()``,
        or not at all). The update needs each element's depth, position and velocity (z_max, stick anchor,
        reversal counter, previous velocity), which one launch recomputes from the inputs with the kinematics
        functions compute() uses (cheaper than storing and re-reading them, and immune to a later compute()
        with other inputs); no element force is evaluated. Only ``at_rest="ema"`` first re-evaluates the element
        forces of this substep, because the EMA's ``force_prev`` is the filtered force.
        """
        inputs = (foot_pos_w, foot_mat_w, foot_lin_vel_w, foot_ang_vel_w, foot_com_w)
        if self.at_rest_code == AT_REST_CODES["ema"]:
            # element forces of this substep for force_prev (not counted twice in nan_count)
            self._eval_points(self, inputs, self._scratch_count)
        # z_max, stick anchor, EMA rigidity, previous velocity (and force in "ema" mode), one launch
        eval_state_update(self, inputs, self._vertical_only)

    def compute_and_update_state(
        self,
        foot_pos_w: wp.array,
        foot_mat_w: wp.array,
        foot_lin_vel_w: wp.array,
        foot_ang_vel_w: wp.array,
        foot_com_w: wp.array,
        wrench_out: wp.array,
    ) -> None:
        """compute() then update_state() with the same inputs: this substep's wrench, then the memory advanced.

        On the fused 3D-RFT path this is one launch: each lane evaluates its elements from the old state and
        then advances their state (it owns those entries: no race), with the functions the two-launch sequence
        uses, so wrench, per-point outputs and state equal those of ``compute(); update_state()``. Elsewhere
        (``fused = False``, other models) it is exactly those two calls. Call it once per physics substep, in
        place of both (not in a ``sim.forward()`` that must leave the state alone: use compute() there).
        """
        inputs = (foot_pos_w, foot_mat_w, foot_lin_vel_w, foot_ang_vel_w, foot_com_w)
        if self.fused and self._eval_fused is not None:
            self._eval_fused(self, inputs, wrench_out, advance=True)
            return
        self.compute(*inputs, wrench_out)
        self.update_state(*inputs)

    def reset(self, env_ids: Any = None) -> None:
        """Clear the state of the given worlds (all when None)."""
        ids = np.arange(self.num_worlds) if env_ids is None else _to_numpy(env_ids).astype(np.int64).ravel()
        if len(ids):
            eval_reset_state(self, wp.array(ids.astype(np.int32), dtype=int, device=self.device))
