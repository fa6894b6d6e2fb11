# SPDX-License-Identifier: Apache-2.0
"""Fitted resistive-force-theory coefficients: constants and their loaders, no physics.

Sources (see ``/work/shared/reference/granular-contact-models.md`` sections 1.3 and 2.1):

* 3D-RFT: Agarwal, Goldman & Kamrin, PNAS 120(7) e2214017120 (2023), SI table of c_j^k. Three public
  transcriptions agree on 58 of 60 numbers; ``"pnas"`` holds the majority values (c2^17 = 0.18519,
  c3^16 = -0.02730), ``"gmloco"`` holds GM-Loco's (c3^16 = -0.20770, +20.6 % vertical stiffness of a sole).
* 2D-RFT: Li, Zhang & Goldman, Science 339, 1408 (2013), Table S2, Fourier form.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Literal

import numpy as np

__all__ = [
    "RFT2D_COEFFS",
    "RFT2D_DIMENSIONAL",
    "RFT3D_COEFFS",
    "RFT3D_MONOMIAL_POWERS",
    "Rft2dCoeffSet",
    "load_rft3d_coeffs",
    "resolve_rft3d_coeffs",
]

RFT3D_MONOMIAL_POWERS: np.ndarray = np.array(
    [
        [0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [2, 0, 0], [0, 2, 0], [0, 0, 2],
        [1, 1, 0], [0, 1, 1], [1, 0, 1], [3, 0, 0], [0, 3, 0], [0, 0, 3], [1, 2, 0],
        [2, 1, 0], [0, 1, 2], [0, 2, 1], [2, 0, 1], [1, 0, 2], [1, 1, 1],
    ],
    dtype=np.int64,
)  # fmt: skip
"""Exponents (x1, x2, x3) of the 20 cubic monomials T_k, k = 1..20, in PNAS SI order."""

_PNAS_MAJORITY = np.array(
    [
        [0.00212, -0.06796, -0.02634],
        [-0.02320, -0.10941, -0.03436],
        [-0.20890, 0.04725, 0.45256],
        [-0.43083, -0.06914, 0.00835],
        [-0.00259, -0.05835, 0.02553],
        [0.48872, -0.65880, -1.31290],
        [-0.00415, -0.11985, -0.05532],
        [0.07204, -0.25739, 0.06790],
        [-0.02750, -0.26834, -0.16404],
        [-0.08772, 0.02692, 0.02287],
        [0.01992, -0.00736, 0.02927],
        [-0.45961, 0.63758, 0.95406],
        [0.40799, 0.08997, -0.00131],
        [-0.10107, 0.21069, -0.11028],
        [-0.06576, 0.04748, 0.01487],
        [0.05664, 0.20406, -0.02730],
        [-0.09269, 0.18519, 0.10911],
        [0.01892, 0.04934, -0.04097],
        [0.01033, 0.13527, 0.07881],
        [0.15120, -0.33207, -0.27519],
    ]
)
_GMLOCO = _PNAS_MAJORITY.copy()
_GMLOCO[15, 2] = -0.20770  # c3^16 as in GM-Loco's Material3DRFTCfg (all 2025-26 versions)

RFT3D_COEFFS: dict[str, np.ndarray] = {"pnas": _PNAS_MAJORITY, "gmloco": _GMLOCO}
"""Named 3D-RFT coefficient sets, each [20, 3] (rows k = 1..20, columns c1, c2, c3), dimensionless."""

Rft2dCoeffSet = Literal["generic", "poppy_lp", "poppy_cp"]

RFT2D_COEFFS: dict[str, np.ndarray] = {
    # Order: A00, A10, B11, B01, B-11, C11, C01, C-11, D10 (Li et al. 2013, Table S2).
    "generic": np.array([0.206, 0.169, 0.212, 0.358, 0.055, -0.124, 0.253, 0.007, 0.088]),
    "poppy_lp": np.array([0.051, 0.047, 0.053, 0.083, 0.020, -0.026, 0.057, 0.000, 0.025]),
    "poppy_cp": np.array([0.094, 0.092, 0.092, 0.151, 0.035, -0.039, 0.086, 0.018, 0.046]),
}
"""2D-RFT Fourier coefficient sets; ``generic`` is dimensionless, the poppy-seed sets are in N/cm^3."""

RFT2D_DIMENSIONAL: dict[str, bool] = {"generic": False, "poppy_lp": True, "poppy_cp": True}
"""Whether a 2D set carries units (N/cm^3, scaled by 1e6 to N/m^3) instead of being scaled by xi."""


def load_rft3d_coeffs(path: str | Path) -> np.ndarray:
    """Load a fitted 3D-RFT coefficient set from ``.json``, ``.npy`` or ``.npz``.

    Args:
        path: A ``.json`` file holding a 20x3 list (bare or under key ``"coeffs"``), a ``.npy`` array, or a
            ``.npz`` archive with key ``"coeffs"`` (or exactly one array).

    Returns:
        The coefficients, float64, shape [20, 3].
    """
    path = Path(path)
    if path.suffix == ".json":
        data = json.loads(path.read_text())
        arr = np.asarray(data["coeffs"] if isinstance(data, dict) else data, dtype=np.float64)
    elif path.suffix == ".npy":
        arr = np.load(path).astype(np.float64)
    elif path.suffix == ".npz":
        with np.load(path) as npz:
            key = "coeffs" if "coeffs" in npz.files else npz.files[0]
            if "coeffs" not in npz.files and len(npz.files) != 1:
                raise ValueError(f"{path}: expected key 'coeffs' or a single array, found {npz.files}")
            arr = npz[key].astype(np.float64)
    else:
        raise ValueError(f"{path}: unsupported coefficient file type {path.suffix!r} (use .json/.npy/.npz)")
    return _checked(arr, str(path))


def resolve_rft3d_coeffs(coeffs: str | Path | np.ndarray) -> np.ndarray:
    """Return a [20, 3] float64 coefficient array from a set name, a file path or an array."""
    if isinstance(coeffs, np.ndarray):
        return _checked(coeffs.astype(np.float64), "array")
    if isinstance(coeffs, str) and coeffs in RFT3D_COEFFS:
        return RFT3D_COEFFS[coeffs].copy()
    path = Path(coeffs)
    if path.suffix in (".json", ".npy", ".npz"):
        return load_rft3d_coeffs(path)
    raise ValueError(f"coeffs={coeffs!r}: expected one of {sorted(RFT3D_COEFFS)} or a .json/.npy/.npz file")


def _checked(arr: np.ndarray, name: str) -> np.ndarray:
    """Validate shape [20, 3] and finiteness."""
    if arr.shape != (20, 3) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: 3D-RFT coefficients must be a finite [20, 3] array, got shape {arr.shape}")
    return arr
