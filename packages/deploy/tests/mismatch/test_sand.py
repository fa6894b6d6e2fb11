# SPDX-License-Identifier: Apache-2.0
"""3D-RFT sand as the replay's nominal ground.

The fast sole law against the float64 reference, crater memory, terrain effects exactly nominal at zero on sand.
"""

from __future__ import annotations

import numpy as np
import pytest

from gmloco.deploy.mismatch.benchmark.controller import MotionCfg
from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
from gmloco.deploy.mismatch.benchmark.truth import TruthEffect
from gmloco.deploy.mismatch.effects import EFFECTS
from gmloco.deploy.mismatch.replay import Replayer, sand_replay_cfg
from gmloco.deploy.mismatch.sand import SandCfg, SoleRFT
from gmloco.deploy.mismatch.terrain import TerrainEffectCfg, TerrainParams, sand_effect_forces


def _soles(rng: np.random.Generator, sand: SoleRFT) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Two level soles about 5 mm deep with jittered depths, random cell velocities."""
    shift = np.array([0.3, 0.1, 0.0])
    pts = np.concatenate([sand.points_body, sand.points_body + shift]) + np.array([0.0, 0.0, 0.03])
    pts[:, 2] += rng.normal(0.0, 0.002, len(pts))
    vel = rng.normal(0.0, 0.05, pts.shape)
    return pts, vel, np.array([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0]])


def test_sole_rft_matches_the_contact_reference() -> None:
    """Forces and stick anchors equal gmloco.contact.reference (unloading branch, static friction) to float64."""
    from gmloco.contact import MATERIAL_PRESETS
    from gmloco.contact.reference import advance_stick_anchors, rft3d_unloading_forces

    rng = np.random.default_rng(0)
    sand = SoleRFT()
    cfg, mat = sand.cfg, MATERIAL_PRESETS[sand.cfg.material]
    for _ in range(3):
        pts, vel, nrm = _soles(rng, sand)
        zmax = np.maximum(-pts[:, 2] + rng.normal(0.0, 0.002, len(pts)), 0.0)
        anchors = pts + rng.normal(0.0, 0.002, pts.shape)
        normals = np.repeat(nrm, sand.m, axis=0)
        area = sand.area(2)
        ref = rft3d_unloading_forces(
            pts, normals, vel, area, zmax,
            rho_c=mat.rho_c, mu_int=mat.mu_int, mu_surf=mat.mu_surf, ratio=cfg.unloading_ratio,
            tangential_damping=cfg.tangential_damping, damping=cfg.unloading_damping,
            unloading_speed=cfg.unloading_speed, anchors=anchors, stick_distance=cfg.stick_distance,
        )  # fmt: skip
        sand.zmax, sand.anchor = zmax.copy(), anchors.copy()
        f, _ = sand.forces(pts, vel, nrm)
        # float64 round-off of ~40 N forces (the monomials are formed in a different order)
        np.testing.assert_allclose(f, ref, rtol=0.0, atol=1e-10)
        np.testing.assert_allclose(sand.anchor, advance_stick_anchors(pts, normals, anchors, zmax, 0.002), atol=0.0)


def test_sole_rft_is_depth_linear_and_zero_above_the_surface() -> None:
    """A level sole at rest, virgin loading: F_z = alpha_z(n, g_hat) A d, linear in d, zero above the surface."""
    sand = SoleRFT(SandCfg())
    nrm = np.array([[0.0, 0.0, -1.0]])
    fz = []
    for d in (-0.002, 0.004, 0.008):
        pts = sand.points_body - [0.0, 0.0, sand.points_body[0, 2] + d]
        sand.reset(pts, np.zeros(sand.m))
        f, _ = sand.forces(pts, np.zeros_like(pts), nrm)
        fz.append(f[:, 2].sum())
        np.testing.assert_allclose(f[:, :2].sum(0), 0.0, atol=1e-9)  # symmetric sole: no net shear at rest
    assert fz[0] == 0.0 and fz[1] > 0.0
    np.testing.assert_allclose(fz[2], 2.0 * fz[1], rtol=1e-12)  # RFT: F = alpha z A (Li, Zhang & Goldman 2013)


def test_sand_effects_nominal_at_zero_and_scaling() -> None:
    """Zero parameters return the forces unchanged; zeta scales them by 1 + zeta; cohesion pulls down."""
    rng = np.random.default_rng(1)
    f = rng.normal(0.0, 10.0, (6, 3))
    depth, vz, area = np.array([0.01, 0.0, -0.01, 0.005, 0.02, 0.003]), rng.normal(0, 0.2, 6), np.full(6, 1e-3)
    cfg = TerrainEffectCfg()
    np.testing.assert_array_equal(sand_effect_forces(f, depth, vz, area, TerrainParams(), cfg), f)
    np.testing.assert_allclose(sand_effect_forces(f, depth, vz, area, TerrainParams(zeta=0.5), cfg), 1.5 * f)
    coh = sand_effect_forces(f, depth, vz, area, TerrainParams(cohesion=1000.0), cfg)
    assert np.all(coh[depth > 0, 2] < f[depth > 0, 2]) and np.all(coh[depth <= 0] == f[depth <= 0])


@pytest.fixture(scope="module")
def sand_rec() -> object:
    """1.2 s of the scripted stand on 3D-RFT sand with logged odometry (noise and nuisances on)."""
    rec, _ = generate(
        EpisodeCfg(
            effect=TruthEffect(), duration=1.2, seed=5, ground="sand", odometry=True, motion=MotionCfg(kind="stand")
        )
    )
    return rec


def test_each_effect_exactly_nominal_at_zero_on_sand(sand_rec: object) -> None:
    """On the sand ground too, an all-zero parameter vector of any effect reproduces the nominal replay bit for bit."""
    cfg = sand_replay_cfg()
    cfg.horizon, cfg.stride = 10, 5
    rp = Replayer(sand_rec, cfg)
    starts = rp.segment_starts()[:3]
    nominal = rp.simulate({}, starts)
    for e in EFFECTS:
        np.testing.assert_array_equal(rp.simulate({e.id: np.zeros(e.size)}, starts), nominal, err_msg=e.id)
    for eid, val in (("terrain.stiffness_scale", 0.5), ("terrain.cohesion", 3000.0)):
        assert np.max(np.abs(rp.simulate({eid: np.array([val])}, starts) - nominal)) > 0.0, eid


def test_crater_memory_is_a_running_max_of_depth(sand_rec: object) -> None:
    """z_max >= 0, z_max = 0 for emerged cells, and it never decreases while a cell stays in the sand."""
    rp = Replayer(sand_rec, sand_replay_cfg())
    zm = rp.crater_memory({})
    assert zm.shape == (sand_rec.n, 2 * rp.sand.m)  # type: ignore[union-attr]
    assert np.all(zm >= 0.0) and np.any(zm > 0.002)  # a standing G1 sinks millimetres into dry sand
    inside = (zm[1:] > 0) & (zm[:-1] > 0)
    assert np.all(zm[1:][inside] >= zm[:-1][inside])


def test_sand_defaults_follow_the_contact_models() -> None:
    """SandCfg repeats ContactRFT3DCfg's defaults (the deploy package imports gmloco.contact lazily): keep them equal."""
    from dataclasses import fields

    from gmloco.contact.config import ContactRFT3DCfg

    contact, sand = ContactRFT3DCfg(), SandCfg()
    shared = {f.name for f in fields(SandCfg)} & {f.name for f in fields(ContactRFT3DCfg)}
    assert {"unloading_ratio", "unloading_damping", "unloading_speed", "tangential_damping", "v_eps"} <= shared
    for name in sorted(shared):
        assert getattr(sand, name) == getattr(contact, name), name
