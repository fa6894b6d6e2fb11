# SPDX-License-Identifier: Apache-2.0
"""The MPM evaluation's policies apply the heading rule of their metadata (shared with the deploy runner)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("onnxruntime")

import torch

from gmloco.deploy.export import metadata as m
from gmloco.eval.g1.policy import StudentOnnxPolicy, load_policy

HISTORY, ACTIONS = 3, 2


class _Student(torch.nn.Module):
    """obs [B, 5] + history [B, N, 5] -> actions [B, 2] (fixed weights)."""

    def __init__(self) -> None:
        """Fixed random weights."""
        super().__init__()
        torch.manual_seed(0)
        self.net = torch.nn.Linear(5 * (HISTORY + 1), ACTIONS)

    def forward(self, obs: torch.Tensor, history: torch.Tensor) -> torch.Tensor:
        """Actions."""
        return self.net(torch.cat([obs, history.flatten(1)], dim=1))


def _policy_file(tmp_path: Path, rule: str) -> Path:
    """A tiny student ONNX file whose metadata says ``yaw_command=rule`` (k = 1 1/s, w_z range +-1 rad/s)."""
    terms = [m.ObservationTermSpec("command", 3, 1.0, None, "(v_x, v_y, w_z)"),
             m.ObservationTermSpec("joint_pos", 2, 1.0, None, "q - q_0 [rad]")]  # fmt: skip
    meta = m.PolicyMetadata(
        observation=m.ObservationSpec(terms, HISTORY, "frame_and_history"),  # type: ignore[arg-type]
        joints=m.JointSpec(["a", "b"], [50.0, 50.0], [2.0, 2.0], [0.0, 0.0], [0.25, 0.25], [50.0, 50.0]),
        timing=m.TimingSpec(physics_dt=0.005, decimation=4, policy_dt=0.02),
        contact=m.ContactSpec(
            "rft3d", m.FootColliderSpec(["f"], [0, 1], [0, 1], [0, 1], "sole", [2, 2, 2]), 40.0, {}, {}, {}
        ),
        command=m.CommandSpec("twist", [0.0, 2.5], [-0.5, 0.5], [-1.0, 1.0], rule, 1.0),
    )
    path = tmp_path / f"{rule}.onnx"
    torch.onnx.export(_Student().eval(), (torch.zeros(1, 5), torch.zeros(1, HISTORY, 5)), str(path),
                      input_names=["obs", "history"], output_names=["actions"],
                      dynamic_axes={"obs": {0: "b"}, "history": {0: "b"}}, dynamo=False)  # fmt: skip
    m.write_policy_metadata(path, meta)
    return path


def _walk(policy: StudentOnnxPolicy, headings: list[float]) -> np.ndarray:
    """Step a straight command (1 m/s, w_z = 0) at the given headings [rad]; the observed w_z per step [rad/s]."""
    terms = {"command": np.array([[1.0, 0.0, 0.0]]), "joint_pos": np.zeros((1, 2))}
    for psi in headings:
        policy.act(terms, np.array([psi]))
    return policy.runner.history[0, -len(headings) :, 2]


def test_yaw_target_policy_observes_the_corrected_command(tmp_path: Path) -> None:
    """Straight command, heading drifting 0 -> 0.1 -> 0.3 rad: w_obs = 1.0 * (0 - psi) = 0, -0.1, -0.3 rad/s."""
    policy = load_policy(_policy_file(tmp_path, "yaw_target"))
    assert isinstance(policy, StudentOnnxPolicy)
    np.testing.assert_allclose(_walk(policy, [0.0, 0.1, 0.3]), [0.0, -0.1, -0.3], atol=1e-6)


def test_heading_envs_policy_observes_the_command_as_given(tmp_path: Path) -> None:
    """The same drift under a heading_envs policy leaves w_z at the commanded 0."""
    policy = load_policy(_policy_file(tmp_path, "heading_envs"))
    assert isinstance(policy, StudentOnnxPolicy)
    np.testing.assert_allclose(_walk(policy, [0.0, 0.1, 0.3]), [0.0, 0.0, 0.0])


def test_one_rule_implementation(tmp_path: Path) -> None:
    """The evaluation runs the deploy package's rule object; no second implementation lives in the eval sources."""
    from gmloco.deploy.export.yaw_target import YawTargetCommand

    policy = load_policy(_policy_file(tmp_path, "yaw_target"))
    assert isinstance(policy, StudentOnnxPolicy) and isinstance(policy.runner.yaw_target, YawTargetCommand)
    src = Path(__file__).resolve().parents[2] / "src"
    copies = [
        p for p in src.rglob("*.py") if "def corrected_yaw_rate" in p.read_text() or "yaw_target +" in p.read_text()
    ]
    assert copies == []


def test_reset_resnaps_the_target(tmp_path: Path) -> None:
    """After a lane reset its target snaps to the new heading: no correction on the first step of an episode."""
    policy = load_policy(_policy_file(tmp_path, "yaw_target"))
    assert isinstance(policy, StudentOnnxPolicy)
    _walk(policy, [0.0, 0.2])
    policy.reset([0])
    np.testing.assert_allclose(_walk(policy, [1.0]), [0.0], atol=1e-6)
