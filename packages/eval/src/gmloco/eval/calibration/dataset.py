# SPDX-License-Identifier: Apache-2.0
"""Versioned calibration dataset: per-material sole experiments, units, rate, robot and the fit / held-out split.

One ``.npz`` per material: every experiment's arrays as ``<experiment>/<field>`` and a JSON header ``meta``. The split
is drawn from ``split_seed`` when the dataset is built, before any fitting, and stored in the header.

The torque about the sole centre (``<experiment>/torque`` [N m], [T, 3]) is optional: a file without it reads as
records with an empty torque (forces only), and the fit then has no torque residual for them.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.atomic_io import atomic_write
from gmloco.eval.calibration.protocol import SoleProtocolCfg, SoleRecord

__all__ = [
    "SCHEMA_VERSION",
    "UNITS",
    "CalibrationDataset",
    "ContractError",
    "assign_split",
    "check_contract",
    "load_dataset",
    "save_dataset",
]

SCHEMA_VERSION = 1
"""Version of the file layout; a reader refuses other versions."""
UNITS: dict[str, str] = {"length": "m", "time": "s", "force": "N", "angle": "rad", "mass": "kg"}
"""Units every dataset is written in."""
RECORD_FIELDS = tuple(f.name for f in fields(SoleRecord))
OPTIONAL_FIELDS = ("torque",)
"""Record fields a dataset file may lack (the record keeps its default)."""


class ContractError(ValueError):
    """A dataset that breaks the fitter's contract (robot, units, rate, version); ``name`` says which."""

    def __init__(self, name: str, message: str) -> None:
        super().__init__(f"contract error [{name}]: {message}")
        self.name = name


@dataclass
class CalibrationDataset:
    """Sole experiments of one material on one sand simulator."""

    material: str
    """Medium name (``gmloco.contact.MATERIAL_PRESETS``)."""
    material_params: dict[str, float]
    """rho_c [kg/m^3], mu_int [-], mu_surf [-] of the medium."""
    source: str
    """Sand that produced the records: ``"mpm"`` or ``"rft3d_reference"``."""
    protocol: SoleProtocolCfg
    """Experiment settings (frame time = recording period)."""
    records: dict[str, SoleRecord]
    """Time series per experiment name (``<experiment>`` or ``<experiment>_<repeat>``)."""
    split: dict[str, str]
    """``"fit"`` or ``"heldout"`` per record name."""
    split_seed: int
    """Seed that drew the split."""
    robot: str = "g1"
    """Robot whose sole and weight the protocol uses."""
    extra: dict[str, Any] | None = None
    """Provenance (solver settings, timings, git commit)."""


def assign_split(names: list[str], seed: int, heldout_fraction: float = 0.4) -> dict[str, str]:
    """Return a deterministic fit / held-out split of record names: at least one of each when there are two.

    Depends only on the seed and the set of names (not their order).
    """
    names = sorted(names)
    rng = np.random.default_rng(seed)
    order = [names[i] for i in rng.permutation(len(names))]
    n_held = min(len(names) - 1, max(1, round(heldout_fraction * len(names)))) if len(names) > 1 else 0
    return {n: ("heldout" if i < n_held else "fit") for i, n in enumerate(order)}


def _meta(ds: CalibrationDataset) -> dict[str, Any]:
    """Return the JSON header of a dataset."""
    return {
        "schema_version": SCHEMA_VERSION,
        "units": UNITS,
        "robot": ds.robot,
        "material": ds.material,
        "material_params": ds.material_params,
        "source": ds.source,
        "frame_dt": ds.protocol.frame_dt,
        "protocol": asdict(ds.protocol),
        "split": ds.split,
        "split_seed": ds.split_seed,
        "extra": ds.extra or {},
    }


def save_dataset(ds: CalibrationDataset, path: str | Path) -> Path:
    """Write the dataset atomically (temporary file in the same folder, then rename); return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays = {f"{name}/{f}": getattr(rec, f) for name, rec in ds.records.items() for f in RECORD_FIELDS}
    arrays["meta"] = np.array(json.dumps(_meta(ds)))
    return atomic_write(path, lambda fh: np.savez_compressed(fh, **arrays))  # pyright: ignore[reportArgumentType]


def load_dataset(path: str | Path) -> CalibrationDataset:
    """Read a dataset written by :func:`save_dataset` (raises :class:`ContractError` on another schema version)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(
            f"calibration dataset {path} not found: build it with python -m gmloco.eval.calibration"
        )
    with np.load(path, allow_pickle=False) as z:
        meta = json.loads(str(z["meta"]))
        if meta.get("schema_version") != SCHEMA_VERSION:
            raise ContractError("version", f"{path} has schema {meta.get('schema_version')}, reader {SCHEMA_VERSION}")
        names = sorted({k.split("/")[0] for k in z.files if "/" in k})
        records = {n: SoleRecord(**{f: z[f"{n}/{f}"] for f in RECORD_FIELDS
                                    if f not in OPTIONAL_FIELDS or f"{n}/{f}" in z.files}) for n in names}  # fmt: skip
    known = {f.name for f in fields(SoleProtocolCfg)}
    params: dict[str, Any] = {k: tuple(v) if isinstance(v, list) else v for k, v in meta["protocol"].items()}
    protocol = SoleProtocolCfg(**{k: v for k, v in params.items() if k in known})
    return CalibrationDataset(meta["material"], meta["material_params"], meta["source"], protocol, records,
                              meta["split"], meta["split_seed"], meta["robot"], {**meta["extra"], "meta": meta})  # fmt: skip


def check_contract(ds: CalibrationDataset, robot: str, rate_hz: float | None) -> None:
    """Raise :class:`ContractError` unless the dataset is for ``robot``, in SI units, at ``rate_hz``, evenly sampled.

    Args:
        ds: The dataset.
        robot: Robot the fit is for (``"g1"``).
        rate_hz: Expected recording rate [Hz]; None accepts the dataset's own.
    """
    meta = (ds.extra or {}).get("meta", _meta(ds))
    if ds.robot != robot:
        raise ContractError("robot", f"dataset is for robot {ds.robot!r}, the fit is for {robot!r}")
    if meta.get("units") != UNITS:
        raise ContractError("units", f"dataset units {meta.get('units')} differ from SI {UNITS}; convert it first")
    dt = ds.protocol.frame_dt
    if rate_hz is not None and abs(1.0 / dt - rate_hz) > 1e-6 * rate_hz:
        raise ContractError("rate", f"dataset rate {1.0 / dt:g} Hz, expected {rate_hz:g} Hz")
    for name, rec in ds.records.items():
        steps = np.diff(rec.time)
        if len(steps) and not np.allclose(steps, dt, rtol=1e-6, atol=1e-9):
            raise ContractError("rate", f"record {name!r} is not sampled every frame_dt = {dt} s")
        if np.abs(rec.force).max(initial=0.0) > 1e5:
            raise ContractError("units", f"record {name!r} has forces above 1e5 N: not newtons?")
        if len(rec.torque) and not rec.has_torque:
            raise ContractError("torque", f"record {name!r} has a torque of shape {rec.torque.shape}, not [T, 3]")
    missing = set(ds.records) ^ set(ds.split)
    if missing:
        raise ContractError("split", f"records and split disagree on {sorted(missing)}")


def file_sha256(path: str | Path) -> str:
    """Return the SHA-256 of a file (provenance of a fit)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def read_json_object(path: str | Path, what: str, required: tuple[str, ...] = ()) -> dict[str, Any]:
    """Read a JSON object holding the ``required`` keys (FileNotFoundError / ValueError naming the file)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{what} {path} not found")
    try:
        body = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise ValueError(f"{what} {path} is not JSON: {e}") from e
    if not isinstance(body, dict):
        raise ValueError(f"{what} {path} is not a JSON object")
    missing = [k for k in required if k not in body]
    if missing:
        raise ValueError(f"{what} {path} lacks {missing}: is it the output of the right command?")
    return body
