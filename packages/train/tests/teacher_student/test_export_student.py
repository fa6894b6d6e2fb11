# SPDX-License-Identifier: Apache-2.0
"""The real StudentActor through gmloco.deploy.export: ONNX parity (history included) and the CPU runner."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import torch
from tensordict import TensorDict

from gmloco.train.teacher_student import StudentPPO

export = pytest.importorskip("gmloco.deploy.export")
pytest.importorskip("onnxruntime")


def _metadata(alg: StudentPPO) -> object:
    """Metadata matching the toy student (one observation term, 2 joints)."""
    m = export.metadata
    collider = m.FootColliderSpec(["l", "r"], [-0.1, 0.1], [-0.05, 0.05], [-0.03, 0.0], "sole", [5, 5, 5])
    return m.PolicyMetadata(
        observation=m.ObservationSpec(
            [m.ObservationTermSpec("toy", alg.actor.obs_dim)], alg.actor.history_length, "frame_and_history"
        ),
        joints=m.JointSpec(["a_joint", "b_joint"], [40.0] * 2, [2.0] * 2, [0.0] * 2, [0.25] * 2, [88.0] * 2),
        timing=m.TimingSpec(0.005, 4, 0.02),
        contact=m.ContactSpec("rft3d", collider, 40.0, {}, {}, {}),
        command=m.CommandSpec("twist", [-1.0, 1.0], [-0.5, 0.5], [-0.5, 0.5], "yaw_target", 1.0),
        policy_class="StudentActor",
        latent_dim=alg.actor.latent_dim,
    )


def test_student_onnx_matches_torch_with_history_and_decoded_eta(student_alg: StudentPPO, tmp_path: object) -> None:
    """Export refuses nothing, parity <= 1e-5 on actions, z_hat and psi(z_hat); the runner reproduces the actor."""
    actor = student_alg.actor.eval()
    with torch.no_grad():  # non-trivial normalizer statistics, so they must be exported too
        actor.history_normalizer.update(torch.randn(64, actor.history_frame_dim) * 3.0 + 1.0)  # type: ignore[operator]
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


class _HistoryEnv:
    """Toy env whose ``history`` group is mjlab's own CircularBuffer over the actor frames (reset -> back-fill).

    Episodes time out after ``episode_length`` steps; o_t is random, eta (last critic column) constant per env.
    """

    def __init__(self, num_envs: int, obs_dim: int, history: int, episode_length: int = 6) -> None:
        """Draw the first frame and fill the history with it."""
        from mjlab.utils.buffers import CircularBuffer

        self.num_envs, self.obs_dim, self.max_episode_length = num_envs, obs_dim, episode_length
        self.episode_length_buf = torch.zeros(num_envs, dtype=torch.long)
        self.gen = torch.Generator().manual_seed(3)
        self.buffer = CircularBuffer(history, num_envs, "cpu")
        self.eta = torch.rand(num_envs, 1, generator=self.gen)
        self._push()

    def _push(self) -> None:
        """Append a new random actor frame and rebuild the observation groups."""
        actor = torch.randn(self.num_envs, self.obs_dim, generator=self.gen)
        self.buffer.append(actor)
        critic = torch.cat([actor, self.eta], dim=-1)
        self.obs = TensorDict({"actor": actor, "critic": critic, "history": self.buffer.buffer}, [self.num_envs])

    def get_observations(self) -> TensorDict:
        """Current observation groups."""
        return self.obs

    def step(self, actions: torch.Tensor) -> tuple[TensorDict, torch.Tensor, torch.Tensor, dict]:
        """Advance; envs at their time-out are reset (history rows cleared) before the new frame is appended."""
        del actions
        self.episode_length_buf += 1
        dones = self.episode_length_buf >= self.max_episode_length
        self.buffer.reset(torch.nonzero(dones).flatten())
        self.episode_length_buf[dones] = 0
        self._push()
        return self.obs, torch.zeros(self.num_envs), dones.long(), {}


def test_rollout_parity_check_follows_resets_of_an_mjlab_history_buffer(
    student_alg: StudentPPO, dims: object, tmp_path: object
) -> None:
    """OnnxPolicyRunner, reset on the env's dones, reproduces the torch student over several episodes to 1e-5."""
    from gmloco.train.teacher_student.export_student import rollout_parity_check

    actor = student_alg.actor.eval()
    path = export.export_policy_onnx(actor, tmp_path / "student.onnx", _metadata(student_alg))  # type: ignore[operator]
    env = _HistoryEnv(4, actor.obs_dim, actor.history_length)
    runner = SimpleNamespace(env=env, alg=student_alg, get_inference_policy=lambda: actor)
    checks = rollout_parity_check(runner, path, steps=20, force_reset_after=2)
    assert checks["rollout_resets"] >= 4 + 2 * 3  # envs 0 and 2 at step 2, then every env each 6 steps
    assert checks["rollout_onnx_max_abs_diff"] <= 1e-5 and checks["rollout_eta_max_abs_diff"] <= 1e-5


def test_rollout_parity_check_catches_a_runner_that_ignores_resets(
    student_alg: StudentPPO, dims: object, tmp_path: object, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Without the runner's reset padding the histories diverge after the first reset and the check fails."""
    from gmloco.train.teacher_student.export_student import rollout_parity_check

    actor = student_alg.actor.eval()
    path = export.export_policy_onnx(actor, tmp_path / "student.onnx", _metadata(student_alg))  # type: ignore[operator]
    monkeypatch.setattr(export.OnnxPolicyRunner, "reset", lambda self, env_ids=None: None)
    env = _HistoryEnv(4, actor.obs_dim, actor.history_length)
    runner = SimpleNamespace(env=env, alg=student_alg, get_inference_policy=lambda: actor)
    with pytest.raises(export.ParityError):
        rollout_parity_check(runner, path, steps=12, force_reset_after=2)
