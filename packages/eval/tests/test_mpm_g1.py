# SPDX-License-Identifier: Apache-2.0
"""G1 on a tiny coupled MPM bed (CPU smoke): the sand carries the robot, driven by an exported ONNX policy."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gmloco.contact import MATERIAL_PRESETS
from gmloco.eval.mpm.g1_scene import G1MpmScene, G1MpmSceneCfg, MjlabOnnxPolicy

POLICY = Path(__file__).resolve().parents[3] / "artifacts" / "ppo_rft3d" / "policy.onnx"


@pytest.fixture(scope="module")
def standing_g1() -> G1MpmScene:
    """0.2 s (20 frames of 100 Hz MPM, 200 Hz physics, 50 Hz policy) on a 0.6 x 0.5 x 0.15 m bed, 5 cm voxels."""
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    scene = G1MpmScene(G1MpmSceneCfg(), MATERIAL_PRESETS["dry_sand"], MjlabOnnxPolicy(POLICY))
    scene.run(20)
    return scene


def test_policy_metadata_layout() -> None:
    """The mjlab export's metadata: 29 joints, 6 terms x 5 frames = 480 inputs, gains and q_0 in action order."""
    if not POLICY.exists():
        pytest.skip(f"no exported policy at {POLICY}")
    pol = MjlabOnnxPolicy(POLICY)
    assert pol.obs_dim == 480 and len(pol.spec.joint_names) == 29
    assert pol.spec.joint_names[0] == "left_hip_pitch_joint" and np.isclose(pol.spec.default_joint_pos[3], 0.669)
    a = pol.act({n: np.zeros(d) for n, d in zip(pol.term_names, pol.term_dims, strict=True)})
    assert a.shape == (29,) and np.all(np.isfinite(a))


def test_sand_supports_g1(standing_g1: G1MpmScene) -> None:
    """Over the second half of the run, the sand force on the feet is m g within 50 %; state finite, sinkage small."""
    scene = standing_g1
    scene.test_final()
    ratio = scene.support_ratio(skip=0.5)
    assert 0.5 < ratio < 1.5, f"sand force / weight = {ratio:.2f}"
    sinkage = -np.asarray(scene.sole_z)
    assert np.all(np.isfinite(sinkage)) and sinkage.max() < 0.1, f"max sinkage {sinkage.max():.3f} m"
    assert np.all(np.isfinite(np.asarray(scene.foot_force)))
    assert scene.base_q[-1][2] > 0.6, "pelvis dropped"
