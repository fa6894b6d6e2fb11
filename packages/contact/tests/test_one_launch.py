# SPDX-License-Identifier: Apache-2.0
"""compute_and_update_state(): the fused 3D-RFT pass that also advances the state, in one launch.

It must give what ``compute(); update_state()`` gives with the same inputs (two launches on the fused path): the
same kernel functions evaluate each element from the old state and then advance it, so wrenches (same tile sum),
per-point outputs and every state array are compared bit for bit (``assert_array_equal``) over multi-substep
sequences in which elements stick in their craters (anchor kept), slide (anchor dragged), unload elastically,
leave the sand and re-enter it, and feet carry non-finite inputs. Also run with multi-lane CPU blocks
(``warp.config.enable_cpu_blocks``), where several lanes share a foot and each must write only its own elements.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
import warp as wp

from gmloco.contact import (
    ContactHeuristicRFTCfg,
    ContactModel,
    ContactModelCfg,
    ContactRFT3DCfg,
    g1_foot_box_cfg,
    make_contact_model,
)

W, F = 4, 2
SOLE_Z = -0.03539
"""Sole height in the ankle_roll_link frame [m] (spec 4)."""
STATE = ("depth_max", "ema_tau", "vel_prev", "anchor", "force_prev")
POINTS = ("point_force", "point_depth", "point_vel")


def foot_arrays(*arrays: np.ndarray) -> tuple[wp.array, wp.array, wp.array, wp.array, wp.array]:
    """Convert (pos, rot, lin_vel, ang_vel, com) numpy arrays [W, F, ...] into float32 Warp arrays."""
    pos, rot, vel, ang, com = (a.astype(np.float32) for a in arrays)
    vec = lambda a: wp.array(a, dtype=wp.vec3, device="cpu")  # noqa: E731
    return vec(pos), wp.array(rot, dtype=wp.mat33, device="cpu"), vec(vel), vec(ang), vec(com)


def tilt(roll: float, pitch: float) -> np.ndarray:
    """Return the rotation R_y(pitch) R_x(roll) [3, 3]."""
    c, s = np.cos(roll), np.sin(roll)
    r_x = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    c, s = np.cos(pitch), np.sin(pitch)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]) @ r_x


def stick_slide_sequence(seed: int, steps: int = 10) -> list[tuple[np.ndarray, ...]]:
    """Return foot states [W, F, ...] per 5 ms substep: press 12 mm in, rise a little, then creep and slide.

    World 0 creeps 0.3 mm per substep along x (sole elements stick, then slide once the offset passes 2 mm);
    world 1 slides 3 mm per substep; world 2 is tilted and spins (mixed leading / trailing elements); world 3
    lifts out after the press and comes back down (z_max reset, touch-down anchors). Foot 1 of world 2 gets a
    NaN velocity at one substep (zero force, state as for an emerged element).
    """
    rng = np.random.default_rng(seed)
    rot = np.broadcast_to(np.eye(3), (W, F, 3, 3)).copy()
    rot[2] = tilt(0.25, -0.2), tilt(-0.15, 0.3)
    base = rng.uniform(-0.3, 0.3, (W, F, 3))
    out = []
    for k in range(steps):
        depth = 0.012 if k == 0 else 0.0115 - 0.0002 * k  # press, then unload slowly (elastic branch)
        pos = base.copy()
        pos[..., 2] = -SOLE_Z - depth
        vel = np.zeros((W, F, 3))
        vel[..., 2] = -0.2 if k == 0 else 0.04
        pos[0, :, 0] += 0.0003 * k
        vel[0, :, 0] = 0.06
        pos[1, :, 0] += 0.003 * k
        vel[1, :, 0] = 0.6
        if 3 <= k < 6:
            pos[3, :, 2] += 0.03  # out of the sand
        ang = np.zeros((W, F, 3))
        ang[2] = rng.normal(scale=2.0, size=(F, 3))
        vel[2] += rng.normal(scale=0.2, size=(F, 3))
        if k == 4:
            vel[2, 1, 0] = np.nan
        out.append((pos, rot, vel, ang, pos + np.array([0.03, 0.0, 0.0])))
    return out


def pair(cfg: ContactModelCfg) -> tuple[ContactModel, ContactModel]:
    """Return two identical fused models on per-world materials (dry-sand-like, mu_int and mu_surf spread)."""
    one, two = make_contact_model(cfg, W, F, "cpu"), make_contact_model(cfg, W, F, "cpu")
    for model in (one, two):
        model.set_materials(np.full(W, 1500.0), np.linspace(0.4, 0.8, W), np.linspace(0.3, 0.6, W))
    return one, two


def run_pair(cfg: ContactModelCfg, seq: list[tuple[np.ndarray, ...]]) -> dict[str, int]:
    """Step a one-launch and a two-launch model side by side, compare everything bit for bit after each substep.

    Returns counts of submerged element-substeps whose anchor stuck (unchanged) or slid (moved while already in
    contact), and of elastic-branch element-substeps (0 < depth < z_max), from the two-launch model.
    """
    one, two = pair(cfg)
    counts = {"stick": 0, "slide": 0, "elastic": 0}
    for feet in seq:
        anchor_before = two.anchor.numpy().copy()  # numpy() is a view on the CPU
        depth_max_before = two.depth_max.numpy().copy()
        outs = [wp.zeros((W, F), dtype=wp.spatial_vectorf, device="cpu") for _ in range(2)]
        one.compute_and_update_state(*foot_arrays(*feet), outs[0])
        two.compute(*foot_arrays(*feet), outs[1])
        two.update_state(*foot_arrays(*feet))
        np.testing.assert_array_equal(outs[0].numpy(), outs[1].numpy(), err_msg="wrench")
        for name in (*POINTS, *STATE):
            np.testing.assert_array_equal(getattr(one, name).numpy(), getattr(two, name).numpy(), err_msg=name)
        assert one.nan_count.numpy()[0] == two.nan_count.numpy()[0]
        depth = two.point_depth.numpy()
        in_contact = (depth > 0.0) & (depth_max_before > 0.0)
        moved = np.any(two.anchor.numpy() != anchor_before, axis=-1)
        counts["stick"] += int(np.sum(in_contact & ~moved))
        counts["slide"] += int(np.sum(in_contact & moved))
        counts["elastic"] += int(np.sum((depth > 0.0) & (depth < depth_max_before)))
    return counts


@pytest.mark.parametrize("faces", ["sole", "box"])
def test_one_launch_equals_two_launches_with_stick_and_slide(device: str, faces: Literal["sole", "box"]) -> None:
    """Static friction on: forces, wrenches and state equal compute() + update_state(), sticking and sliding."""
    cfg = ContactRFT3DCfg(collider=g1_foot_box_cfg(faces, 4))
    counts = run_pair(cfg, stick_slide_sequence(seed=len(faces)))
    assert counts["stick"] > 50 and counts["slide"] > 50 and counts["elastic"] > 100, counts


@pytest.mark.parametrize("at_rest", ["none", "ema"])
def test_one_launch_equals_two_launches_other_modes(device: str, at_rest: Literal["none", "ema"]) -> None:
    """Without static friction, and in ``"ema"`` mode (force_prev = this substep's filtered force)."""
    cfg = ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 3), at_rest=at_rest)
    run_pair(cfg, stick_slide_sequence(seed=7, steps=6))


def test_one_launch_with_cpu_blocks(device: str) -> None:
    """Several lanes per foot block (enable_cpu_blocks): each lane advances only its own elements' state."""
    previous = wp.config.enable_cpu_blocks
    wp.config.enable_cpu_blocks = True
    try:
        counts = run_pair(ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 5)), stick_slide_sequence(seed=2, steps=5))
    finally:
        wp.config.enable_cpu_blocks = previous
    assert counts["stick"] > 0 and counts["slide"] > 0, counts


def test_unfused_and_other_models_fall_back_to_two_calls(device: str) -> None:
    """Fall back to compute() + update_state() with fused = False and for models without a fused pass: same results."""
    seq = stick_slide_sequence(seed=4, steps=4)
    for cfg, fused in ((ContactRFT3DCfg(collider=g1_foot_box_cfg("sole", 3)), False), (ContactHeuristicRFTCfg(), True)):
        one, two = pair(cfg)
        one.fused = two.fused = fused
        for feet in seq:
            outs = [wp.zeros((W, F), dtype=wp.spatial_vectorf, device="cpu") for _ in range(2)]
            one.compute_and_update_state(*foot_arrays(*feet), outs[0])
            two.compute(*foot_arrays(*feet), outs[1])
            two.update_state(*foot_arrays(*feet))
            np.testing.assert_array_equal(outs[0].numpy(), outs[1].numpy())
            for name in STATE:
                np.testing.assert_array_equal(getattr(one, name).numpy(), getattr(two, name).numpy(), err_msg=name)
