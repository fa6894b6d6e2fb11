# SPDX-License-Identifier: Apache-2.0
"""Coefficient sets and loaders."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gmloco.contact import RFT3D_COEFFS, load_rft3d_coeffs
from gmloco.contact.coefficients import resolve_rft3d_coeffs


def test_sets_differ_only_in_the_disputed_entry() -> None:
    """Pnas and gmloco agree except c3^16 (-0.02730 vs -0.20770); both hold c2^17 = 0.18519 (spec 1.3)."""
    diff = np.argwhere(RFT3D_COEFFS["pnas"] != RFT3D_COEFFS["gmloco"])
    np.testing.assert_array_equal(diff, [[15, 2]])
    assert RFT3D_COEFFS["pnas"][15, 2] == -0.02730 and RFT3D_COEFFS["gmloco"][15, 2] == -0.20770
    assert RFT3D_COEFFS["pnas"][16, 1] == 0.18519
    # f(1, 1, 1) = column sums (spec 5.1 note)
    np.testing.assert_allclose(RFT3D_COEFFS["pnas"].sum(0), [-0.27614, -0.31492, -0.28468], atol=1e-10)
    np.testing.assert_allclose(RFT3D_COEFFS["gmloco"].sum(0)[2], -0.46508, atol=1e-10)


@pytest.mark.parametrize("suffix", [".json", ".npy", ".npz"])
def test_fitted_set_round_trips_through_files(tmp_path: Path, suffix: str) -> None:
    """A fitted [20, 3] set saved as json/npy/npz loads back unchanged."""
    coeffs = np.random.default_rng(1).normal(size=(20, 3))
    path = tmp_path / f"fit{suffix}"
    if suffix == ".json":
        path.write_text(json.dumps({"coeffs": coeffs.tolist()}))
    elif suffix == ".npy":
        np.save(path, coeffs)
    else:
        np.savez(path, coeffs=coeffs)
    np.testing.assert_array_equal(load_rft3d_coeffs(path), coeffs)
    np.testing.assert_array_equal(resolve_rft3d_coeffs(str(path)), coeffs)


def test_bad_coefficients_are_rejected(tmp_path: Path) -> None:
    """Wrong shapes and unknown names fail with a clear message."""
    path = tmp_path / "bad.npy"
    np.save(path, np.zeros((19, 3)))
    with pytest.raises(ValueError, match=r"\[20, 3\]"):
        load_rft3d_coeffs(path)
    with pytest.raises(ValueError, match="expected one of"):
        resolve_rft3d_coeffs("pnas_typo")
