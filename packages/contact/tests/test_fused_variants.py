# SPDX-License-Identifier: Apache-2.0
"""Fused 3D-RFT kernel variants (register caps, without per-point outputs): same results bit for bit.

The variants exist for benchmarks (benchmarks/gpu/bench_contact.py ``--variants``). Each must give what the default
kernels give: wrench, per-point outputs and state compared with ``assert_array_equal`` over a substep sequence with
pressing, unloading (elastic branch), sliding, lift-off and a non-finite foot. On the CPU the register caps are
no-ops (the CPU build ignores them), so there the check covers the variant plumbing; the GPU benchmark records each variant's difference to the default (``max_rel_diff_vs_default``).
"""

from __future__ import annotations

import numpy as np
import pytest
import warp as wp

from gmloco.contact import ContactModel, ContactRFT3DCfg, g1_foot_box_cfg, make_contact_model
from gmloco.contact.kernels_rft3d import FUSED_VARIANTS, fused_kernel

W, F = 3, 2
SOLE_Z = -0.03539
"""Sole height in the ankle_roll_link frame [m] (spec 4)."""
COMPARED = ("point_force", "point_depth", "point_vel", "depth_max", "ema_tau", "vel_prev", "anchor", "force_prev")


def sequence(steps: int = 6) -> list[tuple[wp.array, wp.array, wp.array, wp.array, wp.array]]:
    """Return foot inputs (pos, rot, lin_vel, ang_vel, com) per substep: press, unload, slide, lift, a NaN."""
    rng = np.random.default_rng(3)
    base = rng.uniform(-0.3, 0.3, (W, F, 3))
    out = []
    for k in range(steps):
        pos = base.copy()
        pos[..., 2] = -SOLE_Z - (0.012 if k == 0 else 0.0115 - 0.0002 * k)
        pos[1, :, 0] += 0.003 * k  # world 1 slides
        if k in (2, 3):
            pos[2, :, 2] += 0.03  # world 2 lifts out and comes back
        vel = np.zeros((W, F, 3))
        vel[..., 2] = -0.2 if k == 0 else 0.04
        vel[1, :, 0] = 0.6
        ang = rng.normal(scale=1.0, size=(W, F, 3))
        if k == 4:
            vel[0, 1, 0] = np.nan
        rot = np.broadcast_to(np.eye(3), (W, F, 3, 3))
        vec = lambda a: wp.array(a.astype(np.float32), dtype=wp.vec3, device="cpu")  # noqa: E731
        mat = wp.array(rot.astype(np.float32), dtype=wp.mat33, device="cpu")
        out.append((vec(pos), mat, vec(vel), vec(ang), vec(pos + np.array([0.03, 0.0, 0.0]))))
    return out


def model(variant: str) -> ContactModel:
    """Return a 3D-RFT model (six-face 3x3 collider, static friction on) launching the given fused variant."""
    m = make_contact_model(ContactRFT3DCfg(collider=g1_foot_box_cfg("box", 3)), W, F, "cpu")
    m.set_materials(np.full(W, 1500.0), np.linspace(0.4, 0.8, W), np.linspace(0.3, 0.6, W))
    m.fused_variant = variant  # type: ignore[attr-defined]
    return m


@pytest.mark.parametrize("variant", [v for v in FUSED_VARIANTS if v != "default"])
def test_variant_equals_default(device: str, variant: str) -> None:
    """compute() and compute_and_update_state() of a variant equal the default kernels' bit for bit."""
    ref, var = model("default"), model(variant)
    elastic = 0
    for feet in sequence():
        depth_max_before = ref.depth_max.numpy().copy()
        for step in (False, True):  # compute() on the old state, then the one-launch step
            outs = [wp.zeros((W, F), dtype=wp.spatial_vectorf, device="cpu") for _ in range(2)]
            for m, out in zip((ref, var), outs, strict=True):
                pos, rot, vel, ang, com = feet
                (m.compute_and_update_state if step else m.compute)(pos, rot, vel, ang, com, out)
            np.testing.assert_array_equal(outs[1].numpy(), outs[0].numpy(), err_msg=f"wrench step={step}")
            for name in COMPARED:
                a, b = getattr(var, name).numpy(), getattr(ref, name).numpy()
                np.testing.assert_array_equal(a, b, err_msg=f"{name} step={step}")
            assert var.nan_count.numpy()[0] == ref.nan_count.numpy()[0]
            if not step:
                depth = ref.point_depth.numpy()
                elastic += int(np.sum((depth > 0.0) & (depth < depth_max_before)))
    assert elastic > 20 and np.abs(ref.point_force.numpy()).max() > 0.0


def test_variant_kernels() -> None:
    """Each register cap is one kernel (default names kept); unknown refused."""
    assert fused_kernel("default", False).key == "rft3d_foot_wrench_kernel"
    assert fused_kernel("default", True).key == "rft3d_foot_step_kernel"
    assert fused_kernel("cap96", False) is fused_kernel("default", False)  # both capped at 96
    assert fused_kernel("nocap", False).key == "rft3d_foot_wrench_kernel_maxregnone"
    assert fused_kernel("nocap", True).key == "rft3d_foot_step_kernel_maxregnone"
    assert fused_kernel("default", True, points=False).key == "rft3d_foot_step_kernel_nopoints"
    assert fused_kernel("cap80", False, points=False).key == "rft3d_foot_wrench_kernel_maxreg80_nopoints"
    assert fused_kernel("cap80", True).key == "rft3d_foot_step_kernel_maxreg80"
    with pytest.raises(ValueError, match="unknown fused variant"):
        fused_kernel("fast", False)


def test_without_point_outputs_same_wrench_and_state(device: str) -> None:
    """``point_outputs`` False: the same wrench and state bit for bit, and the per-point arrays stay unwritten."""
    ref, var = model("default"), model("default")
    var.point_outputs = False
    for feet in sequence():
        for step in (False, True):
            outs = [wp.zeros((W, F), dtype=wp.spatial_vectorf, device="cpu") for _ in range(2)]
            for m, out in zip((ref, var), outs, strict=True):
                (m.compute_and_update_state if step else m.compute)(*feet, out)
            np.testing.assert_array_equal(outs[1].numpy(), outs[0].numpy(), err_msg=f"wrench step={step}")
            for name in COMPARED[3:]:
                np.testing.assert_array_equal(getattr(var, name).numpy(), getattr(ref, name).numpy(), err_msg=name)
    assert np.abs(ref.point_force.numpy()).max() > 0.0
    for name in COMPARED[:3]:
        assert not getattr(var, name).numpy().any(), name
