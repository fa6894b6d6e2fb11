# SPDX-License-Identifier: Apache-2.0
"""Fit the 3D-RFT extension terms to the fit split of a calibration dataset; judge them on the held-out split.

The model is the float64 reference (:mod:`gmloco.contact.reference.rft3d_extensions`) driven by the recorded sole
kinematics; ``scipy.optimize.least_squares`` minimizes the force residual over the fit records, divided by the
single-stance weight. The fit is accepted only if the held-out RMS force error falls below that of the published
3D-RFT by ``min_improvement``; only then is a new default written.

Yaw torque: records that carry the torque about the sole centre (the ``twist`` experiment turns a loaded sole about
the vertical) add a torque-about-z residual, ``torque_weight`` (tau_z,model - tau_z,data) / (W l), W the single-stance
weight [N] and l the sole's half-length [m]: a torque error reads as the lateral force error at the sole's toe in
units of the weight, the same scale as the force residual. tau_z comes only from horizontal element forces, so it
informs ``lateral_scale`` where the presses cannot. Torque errors are reported per split; acceptance stays on the
held-out force error. Records without a torque (datasets recorded with forces only) add no torque residual.

The datum: an MPM grid lets a sole feel the sand before it reaches the nominal bed top (the top particles' mass
reaches grid nodes up to about a voxel above it), so at sole scale MPM carries load at negative nominal depth. The
fit therefore also fits the height of the surface the sole feels, ``datum`` [m] above the nominal top, in every
variant, and reports the published model's error both at the nominal datum and at its own fitted datum. The datum
is a property of the comparison (of the judge's discretization), not a contact term: it is reported, never written
into the calibrated default.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, RftExtensionsCfg
from gmloco.contact.extensions_io import save_rft_extensions
from gmloco.deploy.atomic_io import atomic_write_json
from gmloco.eval.calibration.dataset import CalibrationDataset, ContractError, check_contract, file_sha256
from gmloco.eval.calibration.rft_sand import centred_sole_collider, replay_wrench

__all__ = [
    "DATUM_BOUNDS",
    "FIT_BOUNDS",
    "FIT_INVERTED",
    "SandFitCfg",
    "SandFitResult",
    "dataset_material",
    "fit_datum",
    "fit_extensions",
    "held_terms",
    "replay_forces",
    "replay_wrenches",
    "rms_by_split",
    "split_error",
    "torque_scale",
]

FIT_BOUNDS: dict[str, tuple[float, float, float]] = {
    "depth_exponent": (0.3, 3.0, 1.0),
    "depth_ref": (0.005, 1.0, 0.05),
    "depth_saturation": (0.0, 200.0, 0.0),
    "lateral_scale": (0.0, 2.0, 1.0),
    "overburden": (0.0, 10.0, 0.0),
    "added_mass": (0.0, 10.0, 0.0),
    "loosening_depth": (0.0, 0.05, 0.0),
    "loosening_length": (0.005, 0.5, 0.05),
    "loosening_keep": (0.0, 0.95, 0.0),
    "erosion_length": (0.0, 1000.0, 50.0),
    "erosion_keep": (0.0, 0.95, 0.2),
    "erosion_restore": (0.0005, 0.05, 0.005),
    "rate_drag": (0.0, 20.0, 0.0),
    "bearing": (0.0, 2.0, 0.0),
}
"""(lower, upper, start) of each fitted value, the start neutral (the term off) but for ``erosion_length``; the
lengths of :data:`FIT_INVERTED` are fitted as their inverse [1/m] (0 = off). Erosion starts at 1 / L = 50 (2 cm):
from 0 the finite-difference step (L ~ 10 km) changes no force, the gradient vanishes and the fit never turns
the term on (basalt and poppy seed, ``results/sand_calibration/``).

With the exponent n != 1, the reference depth sets the law's scale: d_ref (d / d_ref)^n = d_ref^(1 - n) d^n, so the
pair fits a power law C d^n (a stiffer or softer medium than the published one); at n = 1 it has no effect."""

FIT_INVERTED: tuple[str, ...] = ("depth_saturation", "erosion_length")
"""Terms fitted as 1 / value, so that 0 is the term off and the fit moves into it smoothly."""

DATUM_BOUNDS: tuple[float, float, float] = (-0.01, 0.04, 0.0)
"""(lower, upper, start) of the fitted datum: height of the felt sand surface above the nominal bed top [m]."""


@dataclass(frozen=True)
class SandFitCfg:
    """Fit settings."""

    params: tuple[str, ...] = (
        "depth_exponent",
        "depth_ref",
        "depth_saturation",
        "lateral_scale",
        "overburden",
        "added_mass",
    )
    """Extension values to fit (keys of :data:`FIT_BOUNDS`)."""
    plastic_unloading: Literal["off", "on", "both"] = "both"
    """Plastic unloading with footprint memory: fixed off / on, or both fitted and the better fit-split one kept."""
    footprint_radius: float = 0.05
    """Footprint radius used with plastic unloading [m]."""
    at_rest: Literal["none", "unloading"] = "unloading"
    """At-rest mode of the fitted model (the training default: ``"unloading"``)."""
    resolution: int = 3
    """Cells per edge of the replayed sole box."""
    robot: str = "g1"
    """Robot the fit is for (contract)."""
    rate_hz: float | None = None
    """Expected recording rate [Hz] (contract); None accepts the dataset's."""
    min_improvement: float = 0.0
    """Relative held-out error reduction required to accept the fit [-] (0: any reduction)."""
    fit_datum: bool = True
    """Fit the felt surface's height above the nominal bed top in every variant (False: datum 0)."""
    torque_weight: float = 1.0
    """Weight of the yaw-torque residual against the force residual [-] (0: forces only); see :func:`torque_scale`."""
    fixed: tuple[tuple[str, float], ...] = ()
    """Terms held at a value instead of fitted, as (name, value) pairs in the term's own unit (e.g. the added mass a
    set of walks identifies where the sole data leave it at a bound); a name may not be in ``params`` too."""

    def __post_init__(self) -> None:
        """Raise ValueError on a negative torque weight or a fixed term that is unknown, fitted or out of bounds."""
        if not self.torque_weight >= 0.0:
            raise ValueError(f"torque_weight must be >= 0, got {self.torque_weight}")
        for name, value in self.fixed:
            if name not in FIT_BOUNDS:
                raise ValueError(f"fixed term {name!r} is unknown: choose from {list(FIT_BOUNDS)}")
            if name in self.params:
                raise ValueError(f"term {name!r} is both fixed and fitted: drop it from params")
            lo, hi, _ = FIT_BOUNDS[name]
            if name not in FIT_INVERTED and not lo <= value <= hi:
                raise ValueError(f"fixed {name}={value} lies outside its fit bounds [{lo}, {hi}]")
            if not value >= 0.0:
                raise ValueError(f"fixed {name}={value} must be >= 0")


@dataclass
class SandFitResult:
    """Outcome of a fit."""

    extensions: RftExtensionsCfg
    """Fitted terms."""
    error_before: dict[str, float]
    """RMS force error [N] of the published 3D-RFT per split (``fit``, ``heldout``)."""
    error_after: dict[str, float]
    """RMS force error [N] of the fitted model per split."""
    per_record: dict[str, dict[str, float]]
    """Before / after RMS force error [N] per record, with its split; records with a torque add ``torque_before`` /
    ``torque_after``, their RMS yaw-torque error [N m]."""
    accepted: bool
    """Held-out error improved by at least ``min_improvement`` on the published model (at its own datum when fitted)."""
    cost: float
    """Final least-squares cost on the fit split."""
    datum: float = 0.0
    """Fitted height of the felt sand surface above the nominal bed top [m] (0 when not fitted)."""
    error_before_aligned: dict[str, float] | None = None
    """RMS force error [N] of the published 3D-RFT per split at its own fitted datum (None: datum not fitted)."""
    datum_before: float = 0.0
    """The published model's own fitted datum [m]."""
    torque_error_before: dict[str, float] | None = None
    """RMS yaw-torque error [N m] of the published 3D-RFT per split over records with a torque (NaN: none in a
    split); None when no record has a torque."""
    torque_error_after: dict[str, float] | None = None
    """RMS yaw-torque error [N m] of the fitted model per split (as ``torque_error_before``)."""


def dataset_material(ds: CalibrationDataset) -> Any:
    """Return the dataset's MaterialCfg, checking it against the recorded parameters (contract)."""
    if ds.material not in MATERIAL_PRESETS:
        raise ContractError("material", f"unknown material {ds.material!r}")
    mat = MATERIAL_PRESETS[ds.material]
    got = {"rho_c": mat.rho_c, "mu_int": mat.mu_int, "mu_surf": mat.mu_surf}
    if any(abs(got[k] - float(v)) > 1e-6 * max(1.0, abs(float(v))) for k, v in ds.material_params.items()):
        raise ContractError("material", f"dataset material {ds.material_params} differs from the preset's {got}")
    return mat


def _extensions(x: np.ndarray, cfg: SandFitCfg, plastic: bool) -> RftExtensionsCfg:
    """Return the RftExtensionsCfg of parameter vector ``x`` (in ``cfg.params`` order)."""
    values: dict[str, Any] = dict(zip(cfg.params, (float(v) for v in x), strict=True))
    for name in FIT_INVERTED:
        if name in values:
            inv = values.pop(name)
            values[name] = 1.0 / inv if inv > 1e-9 else 0.0
    values.update(dict(cfg.fixed))
    if plastic:
        values.update(plastic_unloading=True, footprint_radius=cfg.footprint_radius)
    return RftExtensionsCfg(**values)


def replay_wrenches(
    ds: CalibrationDataset, ext: RftExtensionsCfg, cfg: SandFitCfg, names: list[str], datum: float = 0.0
) -> dict[str, np.ndarray]:
    """Return the model wrench [T, 6] of each named record: force [N], torque about the sole centre [N m].

    The recorded kinematics drive a fresh memory. ``datum`` [m]: the felt surface's height above the nominal bed
    top; the sole is replayed that much deeper (the lever arms about its centre do not change).
    """
    model = ContactRFT3DCfg(at_rest=cfg.at_rest, extensions=ext)
    col = centred_sole_collider(ds.protocol, "box", cfg.resolution)
    mat = dataset_material(ds)
    shift = np.array([0.0, 0.0, datum])
    records = {n: replace(ds.records[n], pos=ds.records[n].pos - shift) if datum else ds.records[n] for n in names}
    return {n: replay_wrench(records[n], col, model, mat, ds.protocol.frame_dt) for n in names}


def replay_forces(
    ds: CalibrationDataset, ext: RftExtensionsCfg, cfg: SandFitCfg, names: list[str], datum: float = 0.0
) -> dict[str, np.ndarray]:
    """Return the model force [N] [T, 3] of each named record (:func:`replay_wrenches`' force)."""
    return {n: w[:, :3] for n, w in replay_wrenches(ds, ext, cfg, names, datum).items()}


def torque_scale(ds: CalibrationDataset) -> float:
    """Return the yaw-torque residual's unit W l [N m]: single-stance weight times the sole's half-length."""
    return ds.protocol.weight * 0.5 * ds.protocol.sole_size[0]


def rms_by_split(ds: CalibrationDataset, sq: dict[str, np.ndarray]) -> dict[str, float]:
    """Return the RMS over each split's frames of per-frame squared errors ``sq`` (NaN for a split without any).

    Frames whose error is NaN (a record's force unknown there, e.g. a walk's double support) are left out.
    """
    out = {}
    for split in ("fit", "heldout"):
        err = np.concatenate([sq[n] for n in sq if ds.split[n] == split] or [np.zeros(0)])
        known = err[np.isfinite(err)]
        out[split] = float(np.sqrt(np.mean(known))) if known.size else float("nan")
    return out


def _split_errors(
    ds: CalibrationDataset, ext: RftExtensionsCfg, cfg: SandFitCfg, datum: float = 0.0
) -> tuple[dict[str, float], dict[str, float], dict[str, float] | None, dict[str, float]]:
    """Return RMS errors of a model on the dataset at ``datum`` [m].

    Returns (force [N] per split, force per record, yaw torque [N m] per split or None when no record has a torque,
    yaw torque per record with a torque).
    """
    wrenches = replay_wrenches(ds, ext, cfg, list(ds.records), datum)
    sq_f = {n: np.sum((w[:, :3] - ds.records[n].force) ** 2, -1) for n, w in wrenches.items()}
    sq_t = {n: (w[:, 5] - ds.records[n].torque[:, 2]) ** 2 for n, w in wrenches.items() if ds.records[n].has_torque}
    per_f = {n: float(np.sqrt(np.nanmean(e))) if np.isfinite(e).any() else float("nan") for n, e in sq_f.items()}
    per_t = {n: float(np.sqrt(np.mean(e))) for n, e in sq_t.items()}
    return rms_by_split(ds, sq_f), per_f, rms_by_split(ds, sq_t) if sq_t else None, per_t


def split_error(
    ds: CalibrationDataset, ext: RftExtensionsCfg, cfg: SandFitCfg, datum: float = 0.0
) -> tuple[dict, dict]:
    """Return (RMS force error [N] per split, per record) of a model on the dataset at ``datum`` [m]."""
    out, per, _, _ = _split_errors(ds, ext, cfg, datum)
    return out, per


def _fit_one(ds: CalibrationDataset, cfg: SandFitCfg, plastic: bool) -> tuple[RftExtensionsCfg, float, float]:
    """Least-squares fit of ``cfg.params`` (and the datum) on the fit split, plastic unloading on or off.

    Returns (terms, cost, datum [m]).
    """
    from scipy.optimize import least_squares

    names = [n for n in ds.records if ds.split[n] == "fit"]
    data = np.concatenate([ds.records[n].force for n in names])
    known = np.isfinite(data)  # a walk's double-support frames carry no per-foot force (NaN): left out
    twisted = [n for n in names if ds.records[n].has_torque] if cfg.torque_weight > 0.0 else []
    data_tz = np.concatenate([ds.records[n].torque[:, 2] for n in twisted]) if twisted else np.zeros(0)
    scale, scale_tz = ds.protocol.weight, torque_scale(ds) / cfg.torque_weight if twisted else 1.0
    n_terms = len(cfg.params)

    def residual(x: np.ndarray) -> np.ndarray:
        """Force residual of the fit records over W, then the weighted yaw-torque residual over W l [-]."""
        datum = float(x[n_terms]) if cfg.fit_datum else 0.0
        wrenches = replay_wrenches(ds, _extensions(x[:n_terms], cfg, plastic), cfg, names, datum)
        force = (np.where(known, np.concatenate([wrenches[n][:, :3] for n in names]) - data, 0.0) / scale).ravel()
        if not twisted:
            return force
        torque = (np.concatenate([wrenches[n][:, 5] for n in twisted]) - data_tz) / scale_tz
        return np.concatenate([force, torque])

    bounds = [FIT_BOUNDS[p] for p in cfg.params] + ([DATUM_BOUNDS] if cfg.fit_datum else [])
    lo, hi, x0 = (np.array([b[i] for b in bounds], dtype=float) for i in range(3))
    if not bounds:  # nothing to fit (plastic unloading alone): the cost of the fixed model
        return _extensions(x0, cfg, plastic), 0.5 * float(np.sum(residual(x0) ** 2)), 0.0
    res = least_squares(residual, x0, bounds=(lo, hi), x_scale=np.maximum(hi - lo, 1e-3) / 10, diff_step=1e-4)
    return _extensions(res.x[:n_terms], cfg, plastic), float(res.cost), float(res.x[n_terms]) if cfg.fit_datum else 0.0


def held_terms(ext: RftExtensionsCfg) -> tuple[tuple[str, float], ...]:
    """Return the fit terms of ``ext`` as :attr:`SandFitCfg.fixed` pairs; ValueError if it sets any other term."""
    default = RftExtensionsCfg()
    others = {f.name for f in fields(RftExtensionsCfg)} - set(FIT_BOUNDS) - {"dt", "plastic_unloading",
                                                                             "footprint_radius"}  # fmt: skip
    changed = sorted(n for n in others if getattr(ext, n) != getattr(default, n))
    if changed:
        raise ValueError(f"terms {changed} cannot be held in a fit (only {sorted(FIT_BOUNDS)} and plastic unloading)")
    return tuple((n, float(getattr(ext, n))) for n in FIT_BOUNDS)


def fit_datum(ds: CalibrationDataset, ext: RftExtensionsCfg, cfg: SandFitCfg) -> float:
    """Return the datum [m] that fits the dataset's fit split best with every term of ``ext`` held.

    ``cfg`` gives the replay settings (at-rest mode, resolution); its ``params`` and ``fixed`` are replaced.
    """
    held = replace(cfg, params=(), fixed=held_terms(ext), footprint_radius=ext.footprint_radius, fit_datum=True)
    return _fit_one(ds, held, plastic=ext.plastic_unloading)[2]


def fit_extensions(ds: CalibrationDataset, cfg: SandFitCfg) -> SandFitResult:
    """Fit on the fit split, compare held-out errors with the published model; contract checked first."""
    check_contract(ds, cfg.robot, cfg.rate_hz)
    unknown = set(cfg.params) - set(FIT_BOUNDS)
    if unknown:
        raise ValueError(f"unknown fit parameters {sorted(unknown)}: choose from {list(FIT_BOUNDS)}")
    if not any(v == "fit" for v in ds.split.values()):
        raise ContractError("split", "the dataset has no fit records")
    choices = {"off": [False], "on": [True], "both": [False, True]}[cfg.plastic_unloading]
    fits = [_fit_one(ds, cfg, plastic) for plastic in choices]
    ext, cost, datum = min(fits, key=lambda f: f[1])
    before, per_before, torque_before, per_torque_before = _split_errors(ds, RftExtensionsCfg(), cfg)
    aligned, datum_before = None, 0.0
    if cfg.fit_datum:
        _, _, datum_before = _fit_one(ds, replace(cfg, params=()), plastic=False)
        aligned, _ = split_error(ds, RftExtensionsCfg(), cfg, datum_before)
    after, per_after, torque_after, per_torque_after = _split_errors(ds, ext, cfg, datum)
    per: dict[str, dict[str, Any]] = {n: {"split": ds.split[n], "before": per_before[n], "after": per_after[n]}
                                      for n in ds.records}  # fmt: skip
    for n in per_torque_before:
        per[n].update(torque_before=per_torque_before[n], torque_after=per_torque_after[n])
    baseline = aligned if aligned is not None else before  # the terms must beat the published model at its datum
    accepted = bool(after["heldout"] < (1.0 - cfg.min_improvement) * baseline["heldout"])
    return SandFitResult(ext, before, after, per, accepted, cost, datum, aligned, datum_before, torque_before,
                         torque_after)  # fmt: skip


def write_report(result: SandFitResult, path: str | Path, provenance: dict[str, Any]) -> Path:
    """Write the fit report JSON atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    body = {"accepted": result.accepted, "force_error_before": result.error_before,
            "force_error_after": result.error_after, "per_record": result.per_record,
            "extensions": asdict(result.extensions), "cost": result.cost, "datum_m": result.datum,
            "force_error_before_aligned": result.error_before_aligned, "datum_before_m": result.datum_before,
            "torque_z_error_before": result.torque_error_before, "torque_z_error_after": result.torque_error_after,
            **provenance}  # fmt: skip
    return atomic_write_json(path, body)


def write_default(result: SandFitResult, path: str | Path, dataset: str | Path, cfg: SandFitCfg) -> Path | None:
    """Write the fitted terms as the new default only if the fit was accepted; return the path or None."""
    if not result.accepted:
        return None
    provenance = {"dataset": str(dataset), "dataset_sha256": file_sha256(dataset), "fit": asdict(cfg),
                  "force_error_before": result.error_before, "force_error_after": result.error_after,
                  "datum_m": result.datum}  # fmt: skip
    return save_rft_extensions(replace(result.extensions), path, provenance)
