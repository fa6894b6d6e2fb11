# SPDX-License-Identifier: Apache-2.0
"""The yaw-target heading rule: hand-computed steps, re-snap, clip, metadata, and the runner applying it."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from gmloco.deploy.export import PolicyMetadata, YawTargetCfg, YawTargetCommand
from gmloco.deploy.export.yaw_target import corrected_yaw_rate, wrap_to_pi

RULE = YawTargetCfg(stiffness=1.0, limits=(-0.5, 0.5), policy_dt=0.02)


def test_rule_hand_computed_steps() -> None:
    """w_z = 0.25 rad/s, heading held at 0: observed 0.25, 0.255, 0.26 (target integrates 0.25 * 0.02 per step)."""
    rule = YawTargetCommand(RULE, num_envs=1)
    got = [float(rule.step(np.array([0.25]), np.array([0.0]))[0]) for _ in range(3)]
    # step 1 snaps psi_target = 0 (e = 0); then psi_target = 0.005, 0.010: w_obs = 0.25 + 1.0 * e
    np.testing.assert_allclose(got, [0.25, 0.255, 0.26], atol=1e-12)


def test_rule_holds_heading_under_a_straight_command() -> None:
    """w_z = 0, heading drifted to 0.1 rad after the snap at 0: w_obs = 1.0 * (0 - 0.1) = -0.1 rad/s."""
    rule = YawTargetCommand(RULE, num_envs=2)
    rule.step(np.zeros(2), np.zeros(2))
    np.testing.assert_allclose(rule.step(np.zeros(2), np.array([0.1, -0.3])), [-0.1, 0.3], atol=1e-12)


def test_rule_resnaps_and_clips() -> None:
    """An error past pi/2 re-snaps (w_obs = w_z); a large error within it is clipped to the trained range."""
    rule = YawTargetCommand(RULE, num_envs=1)
    rule.step(np.zeros(1), np.zeros(1))
    np.testing.assert_allclose(rule.step(np.array([0.2]), np.array([2.0])), [0.2])  # |0 - 2| > pi/2: re-snap
    np.testing.assert_allclose(rule.yaw_target, [2.0 + 0.2 * 0.02])
    np.testing.assert_allclose(rule.step(np.array([0.2]), np.array([2.004 - 1.2])), [0.5])  # 0.2 + 1.2 clipped
    rule.reset()
    np.testing.assert_allclose(rule.step(np.zeros(1), np.array([-3.0])), [0.0])  # reset: snap again


def test_wrap_and_correction_match_the_training_rule() -> None:
    """The numpy rule equals the training command's torch ``corrected_yaw_rate`` on random inputs (when installed)."""
    commands = pytest.importorskip("gmloco.train.mdp.commands")
    torch = pytest.importorskip("torch")
    rng = np.random.default_rng(0)
    w, e = rng.uniform(-1.5, 1.5, 64), wrap_to_pi(rng.uniform(-10, 10, 64))
    assert np.all(np.abs(e) <= math.pi)
    ref = commands.corrected_yaw_rate(torch.from_numpy(w), torch.from_numpy(e), 0.7, (-1.0, 1.0)).numpy()
    np.testing.assert_allclose(corrected_yaw_rate(w, e, 0.7, (-1.0, 1.0)), ref, atol=1e-12)


def test_cfg_from_metadata(make_metadata: Callable[..., PolicyMetadata]) -> None:
    """yaw_target: k, the last curriculum stage's w_z range and the policy period; heading_envs: no rule."""
    meta = make_metadata()
    assert YawTargetCfg.from_metadata(meta) == YawTargetCfg(1.0, (-0.5, 0.5), 0.02)
    staged = replace(meta, command=replace(meta.command, stages=[{"step": 0, "ang_vel_z": [-0.5, 0.5]},
                                                                 {"step": 9, "ang_vel_z": [-1.0, 1.0]}]))  # fmt: skip
    assert YawTargetCfg.from_metadata(staged) == YawTargetCfg(1.0, (-1.0, 1.0), 0.02)
    assert YawTargetCfg.from_metadata(replace(meta, command=replace(meta.command, yaw_command="heading_envs"))) is None


@pytest.fixture
def exported(
    tmp_path: Path, students: SimpleNamespace, make_metadata: Callable[..., PolicyMetadata]
) -> Callable[[str], Path]:
    """Export the tiny student with the given heading rule; returns the file."""
    pytest.importorskip("torch")
    pytest.importorskip("onnxruntime")
    from gmloco.deploy.export import export_policy_onnx

    def make(rule: str) -> Path:
        meta = make_metadata()
        meta = replace(meta, command=replace(meta.command, yaw_command=rule))
        return export_policy_onnx(students.good(), tmp_path / f"{rule}.onnx", meta)

    return make


def test_runner_feeds_a_yaw_target_policy_the_corrected_command(exported: Callable[[str], Path]) -> None:
    """Raw command (v_x, w_z) = (0.5, 0.25), heading 0: the policy's history holds w_z 0.25, 0.255, 0.26."""
    from gmloco.deploy.export import OnnxPolicyRunner

    runner = OnnxPolicyRunner(exported("yaw_target"), num_envs=2)
    terms = {"command": np.array([[0.5, 0.25], [0.5, 0.0]]), "joint_pos": np.zeros((2, 3))}
    with pytest.raises(ValueError, match="heading"):
        runner.step(terms)
    runner.reset()
    for _ in range(3):
        runner.step(terms, heading=np.array([0.0, 0.2]))
    # the command term's last entry (w_z) of the newest 3 frames, oldest first (tiny metadata: clip [-1, 1], scale 1)
    np.testing.assert_allclose(runner.history[0, -3:, 1], [0.25, 0.255, 0.26], atol=1e-6)
    np.testing.assert_allclose(runner.history[1, -3:, 1], [0.0, 0.0, 0.0], atol=1e-6)  # snapped at 0.2, held
    np.testing.assert_allclose(runner.history[:, -1, 0], [0.5, 0.5])  # v_x untouched
    runner.reset([1])
    runner.step(terms, heading=np.array([0.0, 1.0]))
    np.testing.assert_allclose(runner.history[:, -1, 1], [0.265, 0.0], atol=1e-6)  # lane 1 re-snapped at 1.0


def test_runner_leaves_a_heading_envs_policy_unchanged(exported: Callable[[str], Path]) -> None:
    """A heading_envs policy observes the commanded w_z as given, with or without a heading."""
    from gmloco.deploy.export import OnnxPolicyRunner

    runner = OnnxPolicyRunner(exported("heading_envs"), num_envs=1)
    assert runner.yaw_target is None
    terms = {"command": np.array([[0.5, 0.25]]), "joint_pos": np.zeros((1, 3))}
    runner.step(terms)
    runner.step(terms, heading=np.array([1.0]))
    np.testing.assert_allclose(runner.history[0, -2:, 1], [0.25, 0.25])
