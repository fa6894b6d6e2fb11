# SPDX-License-Identifier: Apache-2.0
"""The real StudentActor through gmloco.deploy.export: ONNX parity (history included) and the CPU runner."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gmloco.train.teacher_student import StudentPPO

export = pytest.importorskip("gmloco.deploy.export")
pytest.importorskip("onnxruntime")


def _metadata(alg: StudentPPO) -> object:
    """Metadata matching the toy student (one 5-wide observation term, 2 joints)."""
    return export.PolicyMetadata(
        joint_names=["a_joint", "b_joint"],
        joint_stiffness=[40.0, 40.0],
        joint_damping=[2.0, 2.0],
        default_joint_pos=[0.0, 0.0],
        action_scale=[0.25, 0.25],
        observation_names=["toy"],
        observation_dims=[alg.actor.obs_dim],
        observation_scale=[1.0],
        observation_clip=[None],
        history_length=alg.actor.history_length,
        policy_dt=0.02,
        latent_dim=alg.actor.latent_dim,
    )


def test_student_onnx_matches_torch_with_history_and_decoded_eta(student_alg: StudentPPO, tmp_path: object) -> None:
    """Export refuses nothing, parity <= 1e-5 on actions, z_hat and psi(z_hat); the runner reproduces the actor."""
    actor = student_alg.actor.eval()
    with torch.no_grad():  # non-trivial normalizer statistics, so they must be exported too
        actor.history_normalizer.update(torch.randn(64, actor.history_frame_dim) * 3.0 + 1.0)
    path = export.export_policy_onnx(actor, tmp_path / "student.onnx", _metadata(student_alg), atol=1e-5)  # type: ignore[operator]
    runner = export.OnnxPolicyRunner(path, num_envs=4)
    gen = torch.Generator().manual_seed(0)
    frames = torch.randn(3, 4, actor.obs_dim, generator=gen)
    for t in range(3):
        action = runner.step(frames[t].numpy())
        obs = {"actor": frames[t], "history": torch.from_numpy(runner.history.copy())}
        with torch.no_grad():
            ref = actor(obs)  # type: ignore[arg-type]
            eta = actor.decode(actor.latent)  # type: ignore[arg-type]
        np.testing.assert_allclose(action, ref.numpy(), atol=1e-5)
        np.testing.assert_allclose(runner.eta, eta.numpy(), atol=1e-5)


def test_export_refuses_a_student_with_stock_rsl_rl_export(student_alg: StudentPPO, tmp_path: object) -> None:
    """Forcing rsl-rl's stock MLPModel.as_onnx onto the student (encoder dropped) is refused."""
    from rsl_rl.models import MLPModel

    actor = student_alg.actor
    actor.as_onnx = lambda verbose: MLPModel.as_onnx(actor, verbose)  # type: ignore[method-assign]
    with pytest.raises(export.EncoderDroppedError):
        export.export_policy_onnx(actor, tmp_path / "x.onnx", _metadata(student_alg))  # type: ignore[operator]
