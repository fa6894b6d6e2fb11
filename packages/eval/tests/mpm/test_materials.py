# SPDX-License-Identifier: Apache-2.0
"""Material mapping into Newton's implicit MPM (issues 5 / 9): what each parameter means, checked on Newton's code.

Diagnosis and measurements: ``results/mpm_eval/MATERIAL_MAPPING_DIAGNOSIS.md``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from gmloco.contact.materials import MATERIAL_PRESETS
from gmloco.eval.mpm.materials import drucker_prager_friction, mpm_material


def test_mapping_fields_and_newton_attributes() -> None:
    """rho_c -> density, mu_int -> DP friction, mu_surf -> collider friction; every attribute exists in Newton."""
    import newton

    m = MATERIAL_PRESETS["dry_sand"]
    mat = mpm_material(m)
    assert mat.density == pytest.approx(m.rho_c) and mat.density == pytest.approx(1500.0)
    assert mat.friction == pytest.approx(drucker_prager_friction(m.mu_int)) and mat.friction == pytest.approx(
        0.7171, abs=1e-4
    )
    assert mat.collider_friction == pytest.approx(m.mu_surf)
    builder = newton.ModelBuilder()
    newton.solvers.SolverImplicitMPM.register_custom_attributes(builder)
    builder.add_particle((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), mass=1.0, radius=0.01)
    model = builder.finalize(device="cpu")
    for name in mat.mpm_attributes():
        assert hasattr(model.mpm, name), name
    # hardening must stay 0: Newton scales the yield pressure by sinh(-h log Jp), which is 0 at Jp = 1 (fresh bed)
    assert mat.hardening == 0.0


def test_drucker_prager_friction_matches_mohr_coulomb_compression() -> None:
    """The cone through Mohr-Coulomb's compression corners: hand values, zero at zero, increasing, bad input refused."""
    assert drucker_prager_friction(0.0) == 0.0
    assert drucker_prager_friction(math.tan(math.radians(30.0))) == pytest.approx(6 * 0.5 / (math.sqrt(3) * 2.5))
    mus = np.linspace(0.0, 1.5, 31)
    assert np.all(np.diff([drucker_prager_friction(float(m)) for m in mus]) > 0.0)
    # in triaxial compression (s2 = s3 = p - q/3, s1 = p + 2q/3) Mohr-Coulomb's limit q/p equals the cone's sqrt(3) mu
    phi = math.atan(0.6)
    q_over_p = 6 * math.sin(phi) / (3 - math.sin(phi))
    assert math.sqrt(3.0) * drucker_prager_friction(0.6) == pytest.approx(q_over_p)
    for bad in (-0.1, float("nan")):
        with pytest.raises(ValueError, match="mu_int"):
            drucker_prager_friction(bad)


YieldProbe = Callable[..., np.ndarray]
"""``(stresses [n, 3, 3], mu, p_max=, hard=, jp=) -> [n, 3]`` rows (r_N, |r_T|, yield stress at r_N)."""


@pytest.fixture(scope="module")
def yield_probe() -> YieldProbe:
    """A Warp kernel evaluating Newton's own yield function on a given stress tensor."""
    import warp as wp
    from newton._src.solvers.implicit_mpm.implicit_mpm_solver_kernels import hardening_law
    from newton._src.solvers.implicit_mpm.rheology_solver_kernels import YieldParamVec, shear_yield_stress
    from warp import fem

    @wp.kernel
    def probe(sig: wp.array[wp.mat33], mu: float, p_max: float, hard: float, jp: float, out: wp.array[wp.vec3]) -> None:
        i = wp.tid()
        h = hardening_law(jp, hard)
        params = YieldParamVec.from_values(mu, p_max * h, 0.0, 0.0, 0.0, 0.0)
        # Newton's stress vector: warp.fem's orthonormal symmetric-tensor dofs, compression positive
        r = fem.SymmetricTensorMapper.value_to_dof_3d(-sig[i])
        r_n = r[0]
        r[0] = 0.0
        ys, _d, _lo, _hi = shear_yield_stress(params, r_n)
        out[i] = wp.vec3(r_n, wp.length(r), ys)  # pyright: ignore[reportIndexIssue]  (Warp kernel store)

    def run(sig: np.ndarray, mu: float, p_max: float = 1.0e12, hard: float = 0.0, jp: float = 1.0) -> np.ndarray:
        s = wp.array(sig.astype(np.float32), dtype=wp.mat33, device="cpu")
        out = wp.zeros(len(sig), dtype=wp.vec3, device="cpu")
        wp.launch(probe, dim=len(sig), inputs=[s, mu, p_max, hard, jp, out], device="cpu")
        return out.numpy()

    return run


def _stress_on_cone(p: float, mu: float, rng: np.random.Generator) -> np.ndarray:
    """A random stress with mean pressure p [Pa] (tension positive) and sqrt(J2) = mu p exactly."""
    a = rng.normal(size=(3, 3))
    dev = 0.5 * (a + a.T)
    dev -= np.trace(dev) / 3.0 * np.eye(3)
    j2 = 0.5 * np.sum(dev * dev)
    return -p * np.eye(3) + dev * (mu * p / math.sqrt(j2))


def test_newton_yield_surface_is_sqrt_j2_le_mu_p(yield_probe: YieldProbe) -> None:
    """``mpm:friction`` = mu of sqrt(J2) <= mu p, the Drucker-Prager form of Dunatunga & Kamrin that 3D-RFT used.

    On random stresses exactly on that cone, Newton's shear norm equals its yield stress (1e-4); with the friction
    read as a Frobenius-norm coefficient (|dev| <= mu p) the ratio would be sqrt(2) instead of 1.
    """
    rng = np.random.default_rng(0)
    mu, p = 0.6, 4.0e3
    sig = np.stack([_stress_on_cone(p, mu, rng) for _ in range(16)])
    out = yield_probe(sig, mu)
    np.testing.assert_allclose(out[:, 0], math.sqrt(1.5) * p, rtol=1e-5)  # r_N = sqrt(3/2) p
    np.testing.assert_allclose(out[:, 1] / out[:, 2], 1.0, rtol=1e-4)  # |r_T| = sqrt(J2) = yield stress


def test_hardening_zeroes_strength_of_fresh_bed(yield_probe: YieldProbe) -> None:
    """With ``hardening`` > 0, a never-compacted particle (Jp = 1) has zero yield pressure, hence no strength."""
    rng = np.random.default_rng(1)
    sig = np.stack([_stress_on_cone(4.0e3, 0.6, rng)])
    assert yield_probe(sig, 0.6, hard=0.0)[0, 2] > 1.0e3
    assert yield_probe(sig, 0.6, hard=5.0, jp=1.0)[0, 2] == pytest.approx(0.0, abs=1e-6)
    assert yield_probe(sig, 0.6, hard=5.0, jp=0.9)[0, 2] > 0.0


@pytest.mark.slow
def test_dense_grid_plate_is_stiffer_and_rate_independent() -> None:
    """Diagnosis measurement (4 cm voxels, 50 iterations, dry sand, horizontal plate pushed down; ~10 s on CPU).

    Measured 2026-11-22: sparse G_z 0.196 (0.5 m/s) / 0.154 (0.1 m/s); dense 0.311 / 0.305. The sparse grid's
    per-step re-allocation loses warm-start information each frame (slower plate = more frames = softer).
    """
    from gmloco.contact.materials import xi_n
    from gmloco.eval.mpm.bed import SandBedCfg
    from gmloco.eval.mpm.box_scene import GridType, MpmSolverCfg
    from gmloco.eval.rft_fit.plate import PlateIntrusionCfg, run_plate_intrusion
    from gmloco.eval.rft_fit.steady import steady_alpha

    m = MATERIAL_PRESETS["dry_sand"]

    def gz(grid_type: GridType, speed: float) -> float:
        cfg = PlateIntrusionCfg(
            plate_size=0.1, plate_thickness=0.02, speed=speed, depth_range=(0.06, 0.12), travel_before_sampling=0.05,
            bed=SandBedCfg(size_x=0.4, size_y=0.4, depth=0.24, center_x=0.0),
            solver=MpmSolverCfg(voxel_size=0.04, max_iterations=50, grid_type=grid_type), device="cpu",
        )  # fmt: skip
        r = run_plate_intrusion(cfg, m, np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, -1.0]))
        return float(steady_alpha(r, cfg.plate_size**2)[0][2] / xi_n(m.rho_c, m.mu_int))

    sparse, dense, dense_slow = gz(GridType.sparse, 0.5), gz(GridType.dense, 0.5), gz(GridType.dense, 0.25)
    assert dense > 1.3 * sparse, (sparse, dense)
    assert abs(dense_slow - dense) < 0.1 * dense, (dense, dense_slow)
