# SPDX-License-Identifier: Apache-2.0
"""compute() paths: fused 3D-RFT pass / tiled per-foot sums (``model.fused = True``) vs per-point pass + per-foot loop.

Both paths evaluate each element with the same functions (``rft3d_element_force`` and the per-model element code)
and share update_state, so element forces, depths, velocities and the state must be bit-identical; wrenches
differ only by the sum order (one block of lanes + a tree on the GPU or with ``warp.config.enable_cpu_blocks``;
on the plain CPU device a block is one lane and the order is the same), atol = 1e-5 of the wrench scale.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest
import warp as wp

from gmloco.contact import (
    MATERIAL_PRESETS,
    ContactConeMultiCfg,
    ContactConeSingleCfg,
    ContactHeuristicRFTCfg,
    ContactRFT3DCfg,
    g1_foot_box_cfg,
    make_contact_model,
    terrain_sinusoid,
    terrain_transition,
)

W, F = 5, 2


def _load_helpers():  # noqa: ANN202
    """Import tests/helpers.py by path (pytest uses --import-mode=importlib)."""
    spec = importlib.util.spec_from_file_location("contact_test_helpers", Path(__file__).with_name("helpers.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_helpers = _load_helpers()
foot_arrays, random_rotations = _helpers.foot_arrays, _helpers.random_rotations

STATE = ("depth_max", "ema_tau", "vel_prev", "anchor")


def feet_sequence(seed: int, steps: int) -> list[tuple[np.ndarray, ...]]:
    """Return ``steps`` random foot states [W, F, ...]: feet 0-4 cm low, pressing, lifting and reversing."""
    rng = np.random.default_rng(seed)
    pos = rng.uniform([-0.5, -0.5, 0.0], [0.5, 0.5, 0.035], (W, F, 3))
    rot = random_rotations(rng, W * F, 0.4).reshape(W, F, 3, 3)
    out = []
    for _ in range(steps):
        vel = rng.normal(scale=0.3, size=(W, F, 3))
        ang = rng.normal(scale=1.5, size=(W, F, 3))
        pos = pos + 0.005 * vel  # 5 ms substeps: elements enter, leave and re-enter their craters
        out.append((pos.copy(), rot, vel, ang, pos + rng.normal(scale=0.02, size=(W, F, 3))))
    return out


def run_both(cfg: object, seed: int, steps: int = 8, terrain: object = None) -> None:
    """Step a fused and a reference model side by side and compare outputs and state after every substep."""
    fast, ref = (make_contact_model(cfg, W, F, "cpu", terrain) for _ in range(2))
    ref.fused = False
    for model in (fast, ref):
        model.set_materials(np.full(W, 1500.0), np.linspace(0.3, 0.9, W), np.linspace(0.2, 0.8, W))
    ema = getattr(cfg, "at_rest", "none") == "ema"
    for feet in feet_sequence(seed, steps):
        wrenches = []
        for model in (fast, ref):
            out = wp.zeros((W, F), dtype=wp.spatial_vector, device="cpu")
            model.compute(*foot_arrays(*feet), out)
            wrenches.append(out.numpy())
            forces = model.point_force.numpy()  # before update_state (the EMA path re-evaluates them)
            depth, vel = model.point_depth.numpy(), model.point_vel.numpy()
            model.update_state(*foot_arrays(*feet))
            if model is fast:
                fast_points = (forces, depth, vel)
        np.testing.assert_array_equal(fast_points[1], depth)
        np.testing.assert_array_equal(fast_points[2], vel)
        np.testing.assert_array_equal(fast_points[0], forces)
        np.testing.assert_allclose(wrenches[0], wrenches[1], atol=1e-5 * max(np.abs(wrenches[1]).max(), 1e-6))
        for name in (*STATE, "force_prev") if ema else STATE:
            np.testing.assert_array_equal(getattr(fast, name).numpy(), getattr(ref, name).numpy(), err_msg=name)
    assert fast.depth_max.numpy().max() > 0.0 and np.abs(wrenches[1]).max() > 0.0


@pytest.mark.parametrize("faces", ["sole", "box"])
@pytest.mark.parametrize("at_rest", ["unloading", "none", "ema"])
def test_rft3d_fused_equals_unfused(device: str, faces: str, at_rest: str) -> None:
    """Fused 3D-RFT compute = per-point pass + per-foot loop on random multi-substep sequences (and same state)."""
    run_both(ContactRFT3DCfg(collider=g1_foot_box_cfg(faces, 5), at_rest=at_rest), seed=len(faces) + len(at_rest))


def test_rft3d_fused_on_terrain_field(device: str) -> None:
    """The fused pass uses the terrain height and the blended material field like the per-point kernel."""
    mats = tuple(MATERIAL_PRESETS[k] for k in ("basalt", "dry_sand", "poppy_seed"))
    terrain = terrain_transition(mats, (-0.2, 0.2), blend=0.1, base=terrain_sinusoid((0.01, 0.005), (0.7, 0.5)))
    run_both(ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 4), coeffs="gmloco"), seed=3, terrain=terrain)


@pytest.mark.parametrize(
    "cfg",
    [ContactHeuristicRFTCfg(collider=g1_foot_box_cfg("box", 4)), ContactConeMultiCfg(), ContactConeSingleCfg()],
    ids=["heuristic", "cone_multi", "cone_single"],
)
def test_other_models_tiled_sum_equals_unfused(device: str, cfg: object) -> None:
    """The tiled per-foot sum gives Heuristic-RFT and cone the same element outputs and wrenches as the loop."""
    run_both(cfg, seed=5)


def test_update_state_independent_of_compute_calls(device: str) -> None:
    """compute() twice (or with other inputs in between, or not at all) then update_state = once then update_state."""
    cfg = ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 3))
    seq = feet_sequence(11, 4)
    out = wp.zeros((W, F), dtype=wp.spatial_vector, device="cpu")
    states = []
    for calls in ((0,), (0, 0), (0, 1), ()):
        model = make_contact_model(cfg, W, F, "cpu")
        for feet in seq[2:]:
            for k in calls:  # k = 1: a compute() at other kinematics (e.g. forward() after the step)
                model.compute(*foot_arrays(*(feet if k == 0 else seq[0])), out)
            model.update_state(*foot_arrays(*feet))
        states.append([getattr(model, name).numpy() for name in STATE])
    for state in states[1:]:
        for a, b in zip(states[0], state, strict=True):
            np.testing.assert_array_equal(a, b)


def test_tiled_kernels_with_cpu_blocks(device: str) -> None:
    """With real multi-lane CPU blocks (warp.config.enable_cpu_blocks) the lane-strided sums still match."""
    previous = wp.config.enable_cpu_blocks
    wp.config.enable_cpu_blocks = True
    try:
        run_both(ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 5)), seed=8, steps=3)
        run_both(ContactHeuristicRFTCfg(collider=g1_foot_box_cfg("box", 3)), seed=9, steps=2)
    finally:
        wp.config.enable_cpu_blocks = previous
