# SPDX-License-Identifier: Apache-2.0
"""The five contact models (3D-RFT, Heuristic-RFT, Cone single/multi, Rigid) and their factory."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
import warp as wp

from gmloco.contact.coefficients import RFT2D_COEFFS, RFT2D_DIMENSIONAL, resolve_rft3d_coeffs
from gmloco.contact.colliders import ColliderBoxCfg, ColliderPoints, box_collider
from gmloco.contact.config import (
    ContactConeMultiCfg,
    ContactConeSingleCfg,
    ContactHeuristicRFTCfg,
    ContactModelCfg,
    ContactRFT3DCfg,
    ContactRigidCfg,
)
from gmloco.contact.kernels_cone import eval_cone_point_forces
from gmloco.contact.kernels_rft2d import eval_heuristic_point_forces
from gmloco.contact.kernels_rft3d import RFT3DCoeffs, eval_rft3d_foot_wrench, eval_rft3d_point_forces
from gmloco.contact.kernels_rft3d_ext import EXT_COLUMNS, make_ext_params, rft_ext_values
from gmloco.contact.kernels_state import eval_zero_wrench
from gmloco.contact.model_base import ContactModel
from gmloco.contact.terrain import TerrainCfg

__all__ = [
    "ContactConeMulti",
    "ContactConeSingle",
    "ContactHeuristicRFT",
    "ContactRFT3D",
    "ContactRigid",
    "cone_points",
    "make_contact_model",
]


class ContactRFT3D(ContactModel):
    """3D-RFT (PNAS 2023) on every collider element."""

    _eval_points = staticmethod(eval_rft3d_point_forces)
    _eval_fused = staticmethod(eval_rft3d_foot_wrench)
    fused_variant: str = "default"
    """Fused kernel variant (:data:`~gmloco.contact.kernels_rft3d.FUSED_VARIANTS`): register caps for benchmarks;
    every variant gives the same results bit for bit."""

    def __init__(
        self, cfg: ContactRFT3DCfg, num_worlds: int, num_feet: int, device: str, terrain: TerrainCfg | None = None
    ) -> None:
        """Build from ``cfg``; see :class:`ContactModel`."""
        super().__init__(cfg, num_worlds, num_feet, device, terrain, box_collider(cfg.collider))
        self.coeffs = RFT3DCoeffs(np.asarray(resolve_rft3d_coeffs(cfg.coeffs), dtype=np.float32))
        """The 20 x 3 coefficients as a by-value kernel parameter (constant-bank operands, no loads)."""
        self.ext_values = wp.array(np.repeat(rft_ext_values(cfg.extensions), num_worlds, 0), dtype=float, device=device)
        """Per-world extension values [W, 7] in ``EXT_COLUMNS`` order (``RftExtensionsCfg``; set_extensions)."""
        self.ext = make_ext_params(cfg.extensions, self.ext_values)
        """Extension flags, values and physics step as one by-value kernel argument (``RftExtParams``)."""
        self.ext_on = not cfg.extensions.is_off
        """Whether the kernels with the extension terms compiled in are launched (else the published model's)."""

    @property
    def is_stateful(self) -> bool:
        """Whether update_state() matters: an at-rest mode, or an extension term that reads element memory."""
        return self.at_rest_code != 0 or self.cfg.extensions.stateful

    def set_extensions(self, env_ids: Any = None, **values: Any) -> None:
        """Set per-world extension values in place (domain randomization); the on/off flags stay those of the cfg.

        Args:
            env_ids: Worlds to update; None = all.
            **values: ``RftExtensionsCfg`` fields of :data:`EXT_COLUMNS`, each [len(env_ids)] or a scalar.
        """
        unknown = set(values) - set(EXT_COLUMNS)
        if unknown:
            raise ValueError(f"set_extensions: unknown {sorted(unknown)}; per-world values are {list(EXT_COLUMNS)}")
        ids = np.arange(self.num_worlds) if env_ids is None else np.asarray(env_ids, dtype=np.int64).ravel()
        table = self.ext_values.numpy().astype(np.float64)
        for name, value in values.items():
            table[ids, EXT_COLUMNS.index(name)] = np.broadcast_to(np.asarray(value, dtype=np.float64), ids.shape)
        for row in np.unique(table, axis=0):  # each distinct row must be a valid configuration
            replace(self.cfg.extensions, **{n: float(v) for n, v in zip(EXT_COLUMNS, row, strict=True)})
        self.ext_values.assign(table)


class ContactHeuristicRFT(ContactModel):
    """Heuristic-RFT baseline (2D-RFT vertical + Coulomb tangential) on every collider element."""

    _eval_points = staticmethod(eval_heuristic_point_forces)
    _vertical_only = 1

    def __init__(
        self,
        cfg: ContactHeuristicRFTCfg,
        num_worlds: int,
        num_feet: int,
        device: str,
        terrain: TerrainCfg | None = None,
    ) -> None:
        """Build from ``cfg``; see :class:`ContactModel`."""
        super().__init__(cfg, num_worlds, num_feet, device, terrain, box_collider(cfg.collider))
        self.coeffs = wp.array(RFT2D_COEFFS[cfg.coeffs], dtype=float, device=device)
        self.dimensional = int(RFT2D_DIMENSIONAL[cfg.coeffs])


def cone_points(collider: ColliderBoxCfg, multi: bool) -> tuple[ColliderPoints, np.ndarray]:
    """Return the cone contact points and their hydraulic radii [m].

    Single: the sole centre with r_h = l_x l_y / (l_x + l_y). Multi: the cell-centred sole grid, each cell
    with r_h of its own cell, which is r_h / n for an n x n grid, so that n^2 pi (r_h / n)^2 = pi r_h^2
    (GM-Loco used linspace spacing l / (n - 1) instead; spec 3.2).
    """
    if not multi:
        pts = ColliderPoints(
            collider.sole_center[None],
            np.array([[0.0, 0.0, -1.0]]),
            np.array([np.diff(collider.x_range)[0] * np.diff(collider.y_range)[0]]),
        )
        return pts, np.array([collider.sole_hydraulic_radius])
    sole = box_collider(
        ColliderBoxCfg(collider.x_range, collider.y_range, collider.z_range, "sole", collider.resolution)
    )
    c_x = np.diff(collider.x_range)[0] / collider.counts[0]
    c_y = np.diff(collider.y_range)[0] / collider.counts[1]
    return sole, np.full(sole.num_points, c_x * c_y / (c_x + c_y))


class ContactConeSingle(ContactModel):
    """Jammed-cone RFT (Choi 2023) at one point per foot; stateful (z_max, EMA, previous velocity)."""

    _eval_points = staticmethod(eval_cone_point_forces)
    _vertical_only = 1
    _multi = False
    fused = False  # one point per foot: the tiled sum costs more than it saves (H100: 12.4 vs 7.6 us compute)
    _always_stateful = True  # plastic unloading needs z_max

    def __init__(
        self, cfg: ContactConeSingleCfg, num_worlds: int, num_feet: int, device: str, terrain: TerrainCfg | None = None
    ) -> None:
        """Build from ``cfg``; see :class:`ContactModel`."""
        points, radii = cone_points(cfg.collider, self._multi)
        super().__init__(cfg, num_worlds, num_feet, device, terrain, points)
        self.radii = wp.array(radii, dtype=float, device=device)
        self.sigma_flat = wp.full(num_worlds, cfg.sigma_flat, dtype=float, device=device)
        self.sigma_cone = wp.full(num_worlds, cfg.sigma_cone, dtype=float, device=device)
        self.k_cone = cfg.nu / math.tan(cfg.theta)
        self.cos_theta = math.cos(cfg.theta)
        self.mass_rate = cfg.c_g * cfg.packing * cfg.grain_density * cfg.nu

    def _validate_extra(self, arrays: dict[str, np.ndarray]) -> None:
        """Accept positive sigma_flat / sigma_cone [N/m^3]."""
        for name in ("sigma_flat", "sigma_cone"):
            if name in arrays and not np.all(np.isfinite(arrays[name]) & (arrays[name] > 0.0)):
                raise ValueError(f"{name} [N/m^3] must lie in (0, inf)")
        super()._validate_extra({k: v for k, v in arrays.items() if k not in ("sigma_flat", "sigma_cone")})


class ContactConeMulti(ContactConeSingle):
    """Cone-RFT at every sole grid point, each with its own state (GM-Loco ConeDRFTMultiPoint)."""

    _multi = True
    fused = True  # many points per foot: the tiled per-foot sum pays off


class ContactRigid(ContactModel):
    """No granular force: compute() writes zero wrenches and the simulator's rigid contact acts."""

    is_rigid = True

    def __init__(
        self, cfg: ContactRigidCfg, num_worlds: int, num_feet: int, device: str, terrain: TerrainCfg | None = None
    ) -> None:
        """Build from ``cfg``; see :class:`ContactModel`."""
        super().__init__(cfg, num_worlds, num_feet, device, terrain, box_collider(cfg.collider))

    def compute(
        self,
        foot_pos_w: wp.array,
        foot_mat_w: wp.array,
        foot_lin_vel_w: wp.array,
        foot_ang_vel_w: wp.array,
        foot_com_w: wp.array,
        wrench_out: wp.array,
    ) -> None:
        """Write zero wrenches."""
        eval_zero_wrench(self, wrench_out)

    def update_state(self, *inputs: Any) -> None:
        """Do nothing: the rigid model is stateless."""


_MODELS: list[tuple[type, Callable[..., ContactModel]]] = [
    (ContactRFT3DCfg, ContactRFT3D),
    (ContactHeuristicRFTCfg, ContactHeuristicRFT),
    (ContactConeMultiCfg, ContactConeMulti),  # before its parent class ContactConeSingleCfg
    (ContactConeSingleCfg, ContactConeSingle),
    (ContactRigidCfg, ContactRigid),
]


def make_contact_model(
    cfg: ContactModelCfg, num_worlds: int, num_feet: int, device: str, terrain: TerrainCfg | None = None
) -> ContactModel:
    """Build the contact model that ``cfg`` describes.

    Args:
        cfg: One of the five contact-model configurations.
        num_worlds: Number of simulated worlds W.
        num_feet: Number of feet per world F.
        device: Warp device, e.g. ``"cpu"`` or ``"cuda:0"``.
        terrain: Free surface and material field; None = flat at z = 0 with per-world materials.
    """
    for cfg_type, model_type in _MODELS:
        if isinstance(cfg, cfg_type):
            return model_type(cfg, num_worlds, num_feet, device, terrain)
    raise TypeError(f"unknown contact-model config {type(cfg).__name__}")
