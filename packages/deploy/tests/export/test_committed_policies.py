# SPDX-License-Identifier: Apache-2.0
"""Every committed policy (``artifacts/*/policy.onnx``) carries valid metadata and runs from it alone."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("onnxruntime")

from gmloco.deploy.export import OnnxPolicyRunner, PolicyMetadata, read_policy_metadata

ARTIFACTS = Path(__file__).resolve().parents[4] / "artifacts"
"""The repository's delivered policies."""
POLICIES = sorted(ARTIFACTS.glob("*/policy.onnx"))
"""Every committed ONNX policy (students and PPO baselines)."""
ENVS, STEPS = 2, 4


def _frame(meta: PolicyMetadata, terms: dict[str, np.ndarray]) -> np.ndarray:
    """o_t written out from the metadata's description: each term clipped, then scaled, in the listed order."""
    parts = []
    for t in meta.observation.terms:
        x = terms[t.name] if t.clip is None else np.clip(terms[t.name], t.clip[0], t.clip[1])
        parts.append(x * np.asarray(t.scale, dtype=np.float32))
    return np.concatenate(parts, axis=1)


def _inputs(meta: PolicyMetadata, frames: list[np.ndarray], names: list[str]) -> dict[str, np.ndarray]:
    """The network inputs of the last step, assembled independently of the runner (oldest frame first)."""
    n = meta.observation.history_length
    padded = [frames[0]] * max(n - len(frames), 0) + frames[-n:]  # repeat_first padding after a reset
    history = np.stack(padded, axis=1)  # [ENVS, N, obs_dim]
    if meta.observation.layout == "frame_and_history":
        return {names[0]: frames[-1], names[1]: history}
    stacked, start = [], 0  # term_stacked: for each term, its N frames oldest first
    for t in meta.observation.terms:
        stacked.append(history[:, :, start : start + t.dim].reshape(ENVS, -1))
        start += t.dim
    return {names[0]: np.concatenate(stacked, axis=1)}


def test_every_delivered_role_has_a_policy() -> None:
    """The PPO baselines and the students are all committed (the glob below is not empty by accident)."""
    names = {p.parent.name for p in POLICIES}
    assert {"ppo_rft3d", "ppo_rigid"} <= names and any(n.startswith("gm_loco_student") for n in names), names


@pytest.mark.parametrize("path", POLICIES, ids=[p.parent.name for p in POLICIES])
def test_committed_policy_runs_from_its_metadata_alone(path: Path) -> None:
    """Metadata validates and equals policy.json; the runner's actions equal onnxruntime on inputs built by hand.

    A ``yaw_target`` policy is stepped with headings that follow its commanded yaw rate exactly, so the observed
    yaw-rate command is the raw one clipped to the trained range.
    """
    import onnxruntime as ort

    meta = read_policy_metadata(path)
    meta.validate()
    assert json.loads((path.parent / "policy.json").read_text()) == meta.to_dict()
    assert len(meta.joints.effort_limit) == len(meta.joints.names) == 29
    assert meta.contact.foot_collider.faces in ("sole", "box") and meta.timing.policy_dt == pytest.approx(0.02)
    runner = OnnxPolicyRunner(path, num_envs=ENVS)
    rng = np.random.default_rng(0)
    frames: list[np.ndarray] = []
    yaw_target = meta.command.yaw_command == "yaw_target"
    heading = np.zeros(ENVS)  # robots that turn exactly as commanded: no heading error to correct
    for _ in range(STEPS):
        terms = {t.name: rng.standard_normal((ENVS, t.dim)).astype(np.float32) for t in meta.observation.terms}
        if not yaw_target:
            actions = runner.step(terms)
            frames.append(_frame(meta, terms))
            continue
        actions = runner.step(terms, heading=heading)
        lo, hi = meta.command.stages[-1]["ang_vel_z"] if meta.command.stages else meta.command.ang_vel_z
        seen = terms | {"command": terms["command"].copy()}
        seen["command"][:, -1] = np.clip(terms["command"][:, -1], lo, hi)  # w_z + k * 0, clipped to the range
        frames.append(_frame(meta, seen))
        heading = heading + terms["command"][:, -1] * meta.timing.policy_dt
    assert actions.shape == (ENVS, 29) and np.isfinite(actions).all()
    runtime = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    names = [i.name for i in runtime.get_inputs()]
    feeds = _inputs(meta, frames, names)
    expected = np.concatenate([runtime.run(None, {k: v[e : e + 1] for k, v in feeds.items()})[0] for e in range(ENVS)])
    np.testing.assert_allclose(actions, expected[:, :29], atol=1e-5)
