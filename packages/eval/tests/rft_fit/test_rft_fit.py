# SPDX-License-Identifier: Apache-2.0
"""The 3D-RFT coefficient fit recovers a known set from synthetic G of the float64 reference model."""

from __future__ import annotations

import numpy as np

from gmloco.contact.coefficients import RFT3D_COEFFS, load_rft3d_coeffs
from gmloco.contact.reference import rft3d_generic
from gmloco.eval.rft_fit.fit import fit_rft3d_coeffs, generic_from_coeffs, save_rft3d_coeffs


def _leading_pairs(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Random unit normals and velocities with n . v > 0 (leading elements)."""
    rng = np.random.default_rng(seed)
    nrm = rng.normal(size=(n, 3))
    vel = rng.normal(size=(n, 3))
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    flip = np.sum(nrm * vel, axis=1) < 0
    vel[flip] *= -1.0
    return nrm, vel


def test_design_matrix_matches_reference_generic() -> None:
    """A(n, v) c equals the contact package's frame-free G for the PNAS set (same formula, float64)."""
    nrm, vel = _leading_pairs(200, 1)
    np.testing.assert_allclose(
        generic_from_coeffs(RFT3D_COEFFS["pnas"], nrm, vel), rft3d_generic(nrm, vel, "pnas"), atol=1e-12
    )


def test_fit_recovers_known_set() -> None:
    """Fitting noiseless reference G recovers all 60 coefficients (full rank: float64 round-off only)."""
    nrm, vel = _leading_pairs(400, 2)
    for name in ("pnas", "gmloco"):
        res = fit_rft3d_coeffs(nrm, vel, rft3d_generic(nrm, vel, name))
        assert res.rank == 60
        # lstsq error ~ cond(A) * eps; cond(A) of a random 1200 x 60 cubic design is < 1e4 -> 1e-9 is ample
        np.testing.assert_allclose(res.coeffs, RFT3D_COEFFS[name], atol=1e-9)
        assert res.residual_rms < 1e-12


def test_fit_with_noise_and_ridge_stays_close(tmp_path) -> None:  # noqa: ANN001
    """With 1 % noise the fit reproduces G within the noise, and the saved set loads in the contact package."""
    nrm, vel = _leading_pairs(400, 3)
    g = rft3d_generic(nrm, vel, "pnas")
    noisy = g + 0.01 * np.random.default_rng(4).normal(size=g.shape)
    res = fit_rft3d_coeffs(nrm, vel, noisy, ridge=1e-3, prior=RFT3D_COEFFS["pnas"])
    # residual of a least-squares fit with 60 of 1200 dof cannot exceed the noise level (0.01)
    assert res.residual_rms <= 0.01 * 1.05
    path = save_rft3d_coeffs(tmp_path / "fit.json", res.coeffs, {"note": "test"})
    np.testing.assert_allclose(load_rft3d_coeffs(path), res.coeffs)


def test_normal_only_rows_recover_set_from_friction_capped_data() -> None:
    """Friction-capped samples keep G.n exactly: fitting only their normal part still recovers the set."""
    nrm, vel = _leading_pairs(600, 5)
    g = rft3d_generic(nrm, vel, "pnas")
    n_hat = nrm / np.linalg.norm(nrm, axis=1, keepdims=True)
    g_n = np.sum(g * n_hat, axis=1, keepdims=True) * n_hat
    capped = np.arange(len(g)) % 2 == 0
    # spec 1.1 step 7 with a tiny mu_surf: the tangential part is replaced, the normal part kept
    g_meas = np.where(capped[:, None], g_n + 0.01 * (g - g_n), g)
    res = fit_rft3d_coeffs(nrm, vel, g_meas, normal_only=capped)
    np.testing.assert_allclose(res.coeffs, RFT3D_COEFFS["pnas"], atol=1e-8)
    # fitting the capped samples in full instead biases the set (the test above would fail)
    biased = fit_rft3d_coeffs(nrm, vel, g_meas)
    assert np.max(np.abs(biased.coeffs - RFT3D_COEFFS["pnas"])) > 1e-3


def test_plate_directions_cover_domain_without_duplicates() -> None:
    """The default sweep spans x1, x2, x3 over [-1, 1]-ish ranges, with no two runs on the same plate motion."""
    from gmloco.eval.rft_fit import RftFitCfg, plate_directions
    from gmloco.eval.rft_fit.fit import rft3d_invariants

    dirs = plate_directions(RftFitCfg())
    lead = np.array([n if n @ v >= 0 else -n for _, n, v in dirs])
    vel = np.array([v for _, _, v in dirs])
    keys = {tuple(np.round(np.concatenate([a, b]), 6)) for a, b in zip(lead, vel, strict=True)}
    assert len(keys) == len(dirs) == 36
    x, _, _ = rft3d_invariants(lead, vel)
    assert x[:, 0].min() < -0.8 and x[:, 0].max() == 1.0  # x1 = sin(gamma): up to down
    assert x[:, 1].min() == 0.0 and x[:, 1].max() == 1.0  # x2 = cos(beta): vertical to horizontal plates
    assert x[:, 2].min() == -1.0 and x[:, 2].max() == 1.0  # x3 = n_e . v
    assert np.any(np.abs(lead[:, 1]) > 0.5)  # normals off the x-z plane: G_theta is measured
