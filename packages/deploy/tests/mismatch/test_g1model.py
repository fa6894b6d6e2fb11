# SPDX-License-Identifier: Apache-2.0
"""The replay model without visual meshes has the dynamics of the full model, bit for bit."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from gmloco.deploy.mismatch.benchmark.chirp import ChirpCfg
from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
from gmloco.deploy.mismatch.benchmark.truth import TruthEffect
from gmloco.deploy.mismatch.g1model import G1SimCfg, build_model, drop_visual_meshes
from gmloco.deploy.mismatch.recording import Recording
from gmloco.deploy.mismatch.replay import Replayer

_INERTIAL = ("body_mass", "body_inertia", "body_ipos", "body_iquat", "body_pos", "body_quat", "dof_armature")


def _with_meshes(rp: Replayer) -> Replayer:
    """Put the full MJCF (visual meshes kept) under a replayer that was built without them."""
    import mujoco

    rp.model = build_model(replace(rp.cfg.sim, visual_meshes=True))
    rp.data, rp._pool = mujoco.MjData(rp.model), []
    return rp


@pytest.mark.parametrize("fixed_base", [False, True], ids=["free", "welded"])
def test_dropping_visual_meshes_keeps_every_inertial(fixed_base: bool) -> None:
    """The meshes are visual only: masses, inertias and frames stay, and the BVH shrinks."""
    full = build_model(G1SimCfg(fixed_base=fixed_base))
    lean = build_model(G1SimCfg(fixed_base=fixed_base, visual_meshes=False))
    assert lean.nmesh == 0 and lean.ngeom < full.ngeom and lean.nbvh < full.nbvh
    for name in _INERTIAL:
        np.testing.assert_array_equal(getattr(lean, name), getattr(full, name), err_msg=name)


def test_replay_without_visual_meshes_is_bit_identical_on_the_plane(null_rec: Recording) -> None:
    """Feet contacts, terrain effects and the floating base do not see the meshes: the output keeps every bit."""
    lean, full = Replayer(null_rec), _with_meshes(Replayer(null_rec))
    starts = lean.segment_starts()[:6]
    for params in ({}, {"terrain.cohesion": np.array([500.0]), "joint.armature": np.array([0.3])}):
        np.testing.assert_array_equal(lean.simulate(params, starts), full.simulate(params, starts))


def test_replay_without_visual_meshes_is_bit_identical_with_a_welded_pelvis() -> None:
    """A welded pelvis: same bits with and without the meshes."""
    rec, _ = generate(
        EpisodeCfg(effect=TruthEffect(), duration=1.5, seed=5, support="gantry", chirp=ChirpCfg(duration=1.5))
    )
    lean, full = Replayer(rec), _with_meshes(Replayer(rec))
    starts = lean.segment_starts()[:6]
    params = {"actuator.backlash": np.array([0.01, 0.02, 0.0]), "body.limb_mass": np.array([0.0, 0.0, 1.0, 0.0])}
    np.testing.assert_array_equal(lean.simulate(params, starts), full.simulate(params, starts))


def test_a_colliding_mesh_is_never_dropped() -> None:
    """A mesh geom that can collide is part of the dynamics: dropping it is refused."""
    import mujoco

    from gmloco.deploy.mismatch.g1model import g1_mjcf_path

    spec = mujoco.MjSpec.from_file(str(g1_mjcf_path()))
    mesh = next(g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH)
    mesh.contype = 1
    with pytest.raises(ValueError, match="can collide"):
        drop_visual_meshes(spec)
