# SPDX-License-Identifier: Apache-2.0
"""OnnxPolicyRunner: history handling (first-step padding, shifting, per-env reset) and parity with torch."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

torch = pytest.importorskip("torch")
pytest.importorskip("onnxruntime")

from gmloco.deploy.export import OnnxPolicyRunner, PolicyMetadata, export_policy_onnx  # noqa: E402


@pytest.fixture
def exported(
    tmp_path: Path, students: SimpleNamespace, make_metadata: Callable[..., PolicyMetadata]
) -> Callable[..., tuple[str, torch.nn.Module]]:
    """Factory: export the tiny student with metadata overrides; return (path, torch wrapper)."""

    def make(**overrides: object) -> tuple[str, torch.nn.Module]:
        model = students.good()
        path = export_policy_onnx(model, tmp_path / "student.onnx", make_metadata(**overrides))
        return str(path), model.as_onnx(verbose=False)

    return make


def _torch_actions(wrapper: torch.nn.Module, obs: np.ndarray, history: np.ndarray) -> np.ndarray:
    """Reference actions from the torch wrapper."""
    with torch.no_grad():
        return wrapper(torch.from_numpy(obs), torch.from_numpy(history))[0].numpy()


def test_runner_reproduces_torch_over_an_episode(
    exported: Callable[..., tuple[str, torch.nn.Module]], dims: SimpleNamespace
) -> None:
    """Ten steps of 3 robots: actions equal torch on the reference history (repeat-first padding) to 1e-5."""
    path, wrapper = exported()
    runner = OnnxPolicyRunner(path, num_envs=3)
    rng = np.random.default_rng(0)
    frames = rng.standard_normal((10, 3, dims.obs_dim)).astype(np.float32)
    for t in range(10):
        # Reference history: frames t-N+1 .. t, indices before 0 clamped to frame 0 (mjlab back-fill)
        idx = np.clip(np.arange(t - dims.history + 1, t + 1), 0, None)
        ref_history = frames[idx].transpose(1, 0, 2)
        actions = runner.step(frames[t])
        np.testing.assert_array_equal(runner.history, ref_history)
        np.testing.assert_allclose(actions, _torch_actions(wrapper, frames[t], ref_history), atol=1e-5)
    assert runner.latent is not None and runner.latent.shape == (3, dims.latent)
    assert runner.eta is not None and runner.eta.shape == (3, 1)


def test_first_step_repeats_the_first_frame(
    exported: Callable[..., tuple[str, torch.nn.Module]], dims: SimpleNamespace
) -> None:
    """After construction, every history frame equals o_0, the current frame last."""
    path, _ = exported()
    runner = OnnxPolicyRunner(path)
    obs = np.arange(dims.obs_dim, dtype=np.float32)
    action = runner.step(obs)
    assert action.shape == (dims.actions,)  # 1-D in, 1-D out
    np.testing.assert_array_equal(runner.history[0], np.tile(obs, (dims.history, 1)))


def test_zero_padding_option(exported: Callable[..., tuple[str, torch.nn.Module]], dims: SimpleNamespace) -> None:
    """With history_padding='zeros', older frames are zero on the first step."""
    path, _ = exported(history_padding="zeros")
    runner = OnnxPolicyRunner(path)
    obs = np.ones(dims.obs_dim, dtype=np.float32)
    runner.step(obs)
    np.testing.assert_array_equal(runner.history[0, :-1], 0.0)
    np.testing.assert_array_equal(runner.history[0, -1], obs)


def test_reset_pads_only_the_reset_envs(
    exported: Callable[..., tuple[str, torch.nn.Module]], dims: SimpleNamespace
) -> None:
    """reset([1]) re-pads env 1 with its next frame; env 0 keeps its shifted history."""
    path, _ = exported()
    runner = OnnxPolicyRunner(path, num_envs=2)
    runner.step(np.zeros((2, dims.obs_dim), dtype=np.float32))
    runner.reset([1])
    new = np.full((2, dims.obs_dim), 7.0, dtype=np.float32)
    runner.step(new)
    np.testing.assert_array_equal(runner.history[0, :-1], 0.0)
    np.testing.assert_array_equal(runner.history[0, -1], new[0])
    np.testing.assert_array_equal(runner.history[1], 7.0)


def test_joint_targets_use_default_pose_and_action_scale(exported: Callable[..., tuple[str, torch.nn.Module]]) -> None:
    """q_target = q_0 + scale * a: q_0 = 0.3, scales (0.25, 0.5), a = (1, -2) -> (0.55, -0.7)."""
    path, _ = exported()
    runner = OnnxPolicyRunner(path)
    np.testing.assert_allclose(runner.joint_targets(np.array([1.0, -2.0])), [0.55, -0.7], rtol=1e-6)
    assert runner.metadata.joints.names == ["left_knee_joint", "right_knee_joint"]
