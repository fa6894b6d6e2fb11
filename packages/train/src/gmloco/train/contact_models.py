# SPDX-License-Identifier: Apache-2.0
"""Adapter from :class:`GranularTaskCfg` to ``gmloco.contact`` (the only train module that imports it).

Per-env materials are drawn as torch tensors and handed to the model's ``set_materials``, which writes them and
their eta / eta_log on the device (no host round trip on reset, which happens almost every step at 4,096 envs).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Literal

import numpy as np
import torch
import warp as wp

import gmloco.contact as gc
from gmloco.contact.extensions_io import load_rft_extensions
from gmloco.contact.kernels_rft3d_ext import EXT_COLUMNS
from gmloco.contact.kernels_state import eval_reset_state
from gmloco.contact.materials import validate_material_arrays
from gmloco.train.config import ContactModelName, GranularTaskCfg, MaterialRangeCfg, SandTerrainCfg

__all__ = [
    "MaterialWriter",
    "build_contact_model",
    "contact_model_cfg",
    "contact_terrain_cfg",
    "extension_dr_columns",
    "reset_model_state",
]

NUM_FEET = 2
"""Feet per robot that carry a granular wrench."""


def contact_model_cfg(
    name: ContactModelName, foot_faces: Literal["sole", "box"] = "sole", extensions_file: str | None = None
) -> Any:
    """Return the ``gmloco.contact`` config of a named contact model; the RFT models sample ``foot_faces``.

    ``"rft3d_calibrated"`` is 3D-RFT with the fitted ``RftExtensionsCfg`` of ``extensions_file`` (required).
    """
    if name == "rft3d_calibrated":
        if extensions_file is None:
            raise ValueError("contact_model 'rft3d_calibrated' needs GranularTaskCfg.rft_extensions_file")
        ext = load_rft_extensions(extensions_file)
        return replace(contact_model_cfg("rft3d", foot_faces), extensions=ext)
    table = {
        "rft3d": gc.ContactRFT3DCfg,
        "heuristic_rft": gc.ContactHeuristicRFTCfg,
        "cone_multi": gc.ContactConeMultiCfg,
        "cone_single": gc.ContactConeSingleCfg,
        "rigid": gc.ContactRigidCfg,
    }
    cfg = table[name]()
    if name in ("rft3d", "heuristic_rft") and foot_faces != cfg.collider.faces:
        cfg = replace(cfg, collider=replace(cfg.collider, faces=foot_faces))
    return cfg


def contact_terrain_cfg(terrain: SandTerrainCfg) -> Any:
    """Map the sand terrain to ``gmloco.contact.TerrainCfg`` (flat at z = 0 or a sinusoid)."""
    if terrain.amplitude == 0.0:
        return gc.terrain_flat(0.0)
    a, lam = terrain.amplitude, terrain.wavelength
    return gc.terrain_sinusoid((a, a), (lam, lam))


def build_contact_model(task: GranularTaskCfg, num_envs: int, device: wp.context.Device) -> tuple[Any, bool]:
    """Build the task's contact model for ``num_envs`` worlds; returns ``(model, stateful)``.

    The model skips its per-point outputs (``point_outputs`` False): the environment reads only the foot wrenches.
    """
    cfg = contact_model_cfg(task.contact_model, task.foot_faces, task.rft_extensions_file)
    terrain = contact_terrain_cfg(task.terrain)
    model = gc.make_contact_model(cfg, num_envs, NUM_FEET, str(device), terrain=terrain)
    model.point_outputs = False  # training reads only the wrenches (set True before install() to inspect points)
    return model, bool(getattr(model, "is_stateful", True))


def reset_model_state(model: Any, env_ids: torch.Tensor) -> None:
    """Clear the contact-model memory of ``env_ids`` without a host round trip (stateless models: no-op).

    ``ContactModel.reset`` converts the ids through numpy; at 4,096 envs some env resets on almost every
    step, so the ids go to the model's reset launcher as a zero-copy Warp view instead.
    """
    if not getattr(model, "is_stateful", True) or env_ids.numel() == 0:
        return
    eval_reset_state(model, wp.from_torch(env_ids.to(torch.int32), dtype=wp.int32))


def extension_dr_columns(model: Any, ranges: dict[str, tuple[float, float]]) -> dict[int, tuple[float, float]]:
    """Return ``{column of model.ext_values: (lo, hi)}`` for DR ranges of RFT extension terms, validated.

    Each name must be a per-world ``RftExtensionsCfg`` value whose term is on in the model (its flag is fixed when
    the model is built), with lo <= hi and both ends valid values.
    """
    if not ranges:
        return {}
    ext = getattr(getattr(model, "cfg", None), "extensions", None)
    if ext is None or not hasattr(model, "ext_values"):
        raise ValueError("rft_extension_ranges need a 3D-RFT contact model (contact_model 'rft3d_calibrated')")
    neutral = gc.RftExtensionsCfg()
    out = {}
    for name, (lo, hi) in ranges.items():
        if name not in EXT_COLUMNS:
            raise ValueError(f"rft_extension_ranges: unknown {name!r}; per-world values are {list(EXT_COLUMNS)}")
        if name in ("overburden", "added_mass", "lateral_scale") and getattr(ext, name) == getattr(neutral, name):
            raise ValueError(f"rft_extension_ranges: term {name!r} is off in the fitted extensions; nothing to vary")
        if not lo <= hi:
            raise ValueError(f"rft_extension_ranges[{name!r}] = {(lo, hi)}: need lo <= hi")
        for bound in (lo, hi):
            replace(ext, **{name: float(bound)})  # RftExtensionsCfg validates the value
        out[EXT_COLUMNS.index(name)] = (float(lo), float(hi))
    return out


class MaterialWriter:
    """Draws per-env materials and writes them into a contact model through its ``set_materials``.

    Args:
        model: A ``gmloco.contact.ContactModel``.
        ranges: DR ranges (or a preset) of the material.
        device: Torch device of the env.
    """

    def __init__(
        self,
        model: Any,
        ranges: MaterialRangeCfg,
        device: str,
        extension_ranges: dict[str, tuple[float, float]] | None = None,
    ) -> None:
        self.ranges = ranges
        self.extension_ranges = extension_dr_columns(model, extension_ranges or {})
        """Column of ``model.ext_values`` -> U[lo, hi] of the RFT extension terms drawn per env on reset."""
        self.device = device
        self.model = model
        self.preset = gc.MATERIAL_PRESETS[ranges.preset] if ranges.preset is not None else None
        lo_hi = lambda r: np.asarray(r, dtype=np.float64)  # noqa: E731
        validate_material_arrays(
            lo_hi(ranges.packing) * lo_hi(ranges.bulk_density), lo_hi(ranges.mu_int), lo_hi(ranges.mu_surf)
        )
        if not 0.0 <= ranges.soft_share <= 1.0:
            raise ValueError(f"material soft_share={ranges.soft_share}: give a share in [0, 1], e.g. 0.25")
        if ranges.soft_share > 0.0:
            lo, hi = ranges.soft_rho_c
            if not 0.0 < lo <= hi:
                raise ValueError(f"material soft_rho_c={ranges.soft_rho_c}: give 0 < low <= high [kg/m^3]")
        names = ("rho_c", "mu_int", "mu_surf", "eta", "sigma_flat", "sigma_cone")
        self.views = {n: wp.to_torch(getattr(model, n)) for n in names if hasattr(model, n)}
        if self.extension_ranges:
            self.views["ext_values"] = wp.to_torch(model.ext_values)  # [W, 7]
        """Zero-copy torch views of the model's per-world parameter arrays, each [W] (read here; written by
        ``set_materials``, except the extension columns of ``ext_values``)."""
        self.pinned: dict[str, torch.Tensor] | None = None
        """Per-env (rho_c, mu_int, mu_surf) used instead of drawing, set by :meth:`pin`."""
        self.held_out = None
        """(rho_c, mu_int) rectangle the uniform draw avoids (``ranges.held_out_*``), or None."""
        if ranges.held_out_rho_c is not None and ranges.held_out_mu_int is not None:
            from gmloco.train.teacher_student.heldout import HeldOutRegionCfg

            self.held_out = HeldOutRegionCfg(rho_c=ranges.held_out_rho_c, mu_int=ranges.held_out_mu_int)

    def pin(self, rho_c: torch.Tensor, mu_int: torch.Tensor, mu_surf: torch.Tensor) -> None:
        """Fix every env's material (each tensor [W]); later resets keep it instead of drawing."""
        validate_material_arrays(rho_c.cpu().numpy(), mu_int.cpu().numpy(), mu_surf.cpu().numpy())
        self.pinned = {
            "rho_c": rho_c.to(self.device),
            "mu_int": mu_int.to(self.device),
            "mu_surf": mu_surf.to(self.device),
        }

    def draw(self, env_ids: torch.Tensor) -> None:
        """Set (pinned, preset) or draw (uniform DR) the material of ``env_ids`` and write it to the model.

        Every material reaches the model through ``ContactModel.set_materials``, the one writer that keeps
        ``eta`` and ``eta_log`` in step with ``(rho_c, mu_int)``.
        """
        n, r = len(env_ids), self.ranges
        if n == 0:
            return
        if self.pinned is not None:
            material = {name: values[env_ids] for name, values in self.pinned.items()}
        elif self.preset is not None:
            names = ("rho_c", "mu_int", "mu_surf")
            material = {k: torch.full((n,), float(getattr(self.preset, k)), device=self.device) for k in names}
        else:
            rho_c = self._uniform(r.packing, n) * self._uniform(r.bulk_density, n)
            if r.soft_share > 0.0:
                soft = torch.rand(n, device=self.device) < r.soft_share
                rho_c = torch.where(soft, self._uniform(r.soft_rho_c, n), rho_c)
            mu_int = self._uniform(r.mu_int, n)
            if self.held_out is not None:
                from gmloco.train.teacher_student.heldout import redraw_outside

                mu_int = redraw_outside(self.held_out, rho_c, mu_int, r.mu_int)
            material = {"rho_c": rho_c, "mu_int": mu_int, "mu_surf": self._uniform(r.mu_surf, n)}
        for name in ("sigma_flat", "sigma_cone"):
            if name in self.views:
                material[name] = self._uniform(getattr(r, name), n)
        self.model.set_materials(env_ids=env_ids, **material)
        for column, bounds in self.extension_ranges.items():
            self.views["ext_values"][env_ids, column] = self._uniform(bounds, n)

    @property
    def eta(self) -> torch.Tensor:
        """Normalized stiffness of every env [-], shape [W] (view)."""
        return self.views["eta"]

    def _uniform(self, bounds: tuple[float, float], n: int) -> torch.Tensor:
        """Draw ``n`` samples from U[bounds]."""
        lo, hi = bounds
        return lo + (hi - lo) * torch.rand(n, device=self.device)
