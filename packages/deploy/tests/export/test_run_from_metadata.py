# SPDX-License-Identifier: Apache-2.0
"""Run exported policies from their ONNX metadata alone: observation assembly, history order, refusals."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("onnxruntime")

import torch

from gmloco.deploy.export import (
    OnnxPolicyRunner,
    PolicyMetadata,
    PolicyMetadataError,
    export_policy_onnx,
    read_policy_metadata,
    write_policy_metadata,
)

STEPS, ENVS = 8, 3


def _heading_envs(meta: PolicyMetadata) -> PolicyMetadata:
    """Return the metadata with the ``heading_envs`` rule: the command is observed as given.

    ``test_yaw_target.py`` covers the ``yaw_target`` correction.
    """
    return replace(meta, command=replace(meta.command, yaw_command="heading_envs", heading_stiffness=0.5))


def _raw_terms(meta: PolicyMetadata, rng: np.random.Generator) -> dict[str, np.ndarray]:
    """Random raw term values ``{name: [ENVS, dim]}``, wide enough (std 2) that the clips act."""
    return {t.name: 2.0 * rng.standard_normal((ENVS, t.dim)).astype(np.float32) for t in meta.observation.terms}


def _frame(meta: PolicyMetadata, terms: dict[str, np.ndarray]) -> np.ndarray:
    """o_t as the metadata documents it: each term clipped, then scaled, concatenated in the listed order."""
    parts = []
    for t in meta.observation.terms:
        x = terms[t.name] if t.clip is None else np.clip(terms[t.name], t.clip[0], t.clip[1])
        parts.append(x * np.asarray(t.scale, dtype=np.float32))
    return np.concatenate(parts, axis=1)


def _histories(meta: PolicyMetadata, frames: list[np.ndarray]) -> list[np.ndarray]:
    """History ``[ENVS, N, obs_dim]`` at every step: frames t-N+1 .. t, oldest first, indices < 0 repeat frame 0."""
    assert meta.observation.history_order == "oldest_first" and meta.observation.history_padding == "repeat_first"
    n = meta.observation.history_length
    stacked = np.stack(frames)  # [T, ENVS, D]
    return [stacked[np.clip(np.arange(t - n + 1, t + 1), 0, None)].transpose(1, 0, 2) for t in range(len(frames))]


def _term_stacked(meta: PolicyMetadata, history: np.ndarray) -> np.ndarray:
    """The ``term_stacked`` input: for each term in order, its N frames oldest first, ``[ENVS, N * obs_dim]``."""
    out, start = [], 0
    for t in meta.observation.terms:
        out.append(history[:, :, start : start + t.dim].reshape(ENVS, -1))
        start += t.dim
    return np.concatenate(out, axis=1)


class _StackedMlp(torch.nn.Module):
    """An mjlab-style actor: one input ``[batch, N * obs_dim]`` stacked term by term."""

    def __init__(self, width: int, actions: int) -> None:
        """Fixed random weights."""
        super().__init__()
        torch.manual_seed(1)
        self.net = torch.nn.Sequential(torch.nn.Linear(width, 16), torch.nn.ELU(), torch.nn.Linear(16, actions))

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        """Actions."""
        return self.net(obs)


@pytest.fixture
def student(
    tmp_path: Path, students: SimpleNamespace, make_metadata: Callable[..., PolicyMetadata]
) -> tuple[Path, Callable[[np.ndarray, np.ndarray], np.ndarray]]:
    """The tiny student exported with full metadata; returns (path, torch actions of (o_t, history))."""
    model = students.good()
    path = export_policy_onnx(model, tmp_path / "student.onnx", _heading_envs(make_metadata()))
    wrapper = model.as_onnx(verbose=False).eval()

    def act(obs: np.ndarray, history: np.ndarray) -> np.ndarray:
        with torch.no_grad():
            return wrapper(torch.from_numpy(obs), torch.from_numpy(np.ascontiguousarray(history)))[0].numpy()

    return path, act


@pytest.fixture
def stacked(
    tmp_path: Path, make_metadata: Callable[..., PolicyMetadata], dims: SimpleNamespace
) -> tuple[Path, Callable[[np.ndarray], np.ndarray]]:
    """A stacked-input actor exported as mjlab does (batch fixed to 1) plus our metadata; (path, torch actions)."""
    meta = _heading_envs(make_metadata(layout="term_stacked", history_length=4, policy_class="MLPModel", latent_dim=0))
    model = _StackedMlp(4 * meta.obs_dim, dims.actions).eval()
    path = tmp_path / "actor.onnx"
    torch.onnx.export(
        model, (torch.zeros(1, 4 * meta.obs_dim),), str(path), input_names=["obs"], output_names=["actions"],
        dynamo=False,
    )  # fmt: skip
    write_policy_metadata(path, meta)

    def act(obs: np.ndarray) -> np.ndarray:
        with torch.no_grad():
            return model(torch.from_numpy(obs)).numpy()

    return path, act


def test_student_runs_from_its_metadata_alone(
    student: tuple[Path, Callable[[np.ndarray, np.ndarray], np.ndarray]],
) -> None:
    """Raw terms + the file's metadata only: the runner's actions equal torch on the documented o_t and history."""
    path, torch_act = student
    meta = read_policy_metadata(path)  # everything below reads only this and the file
    runner = OnnxPolicyRunner(path, num_envs=ENVS)
    rng = np.random.default_rng(0)
    terms = [_raw_terms(meta, rng) for _ in range(STEPS)]
    frames = [_frame(meta, t) for t in terms]
    for t, history in enumerate(_histories(meta, frames)):
        actions = runner.step(terms[t])
        np.testing.assert_array_equal(runner.history, history)
        np.testing.assert_allclose(actions, torch_act(frames[t], history), atol=1e-5)


def test_stacked_actor_runs_from_its_metadata_alone(stacked: tuple[Path, Callable[[np.ndarray], np.ndarray]]) -> None:
    """The term-stacked layout (mjlab's flattened per-term history, batch fixed to 1) reproduces torch for 3 envs."""
    path, torch_act = stacked
    meta = read_policy_metadata(path)
    runner = OnnxPolicyRunner(path, num_envs=ENVS)
    rng = np.random.default_rng(1)
    terms = [_raw_terms(meta, rng) for _ in range(STEPS)]
    frames = [_frame(meta, t) for t in terms]
    for t, history in enumerate(_histories(meta, frames)):
        actions = runner.step(terms[t])
        np.testing.assert_allclose(actions, torch_act(_term_stacked(meta, history)), atol=1e-5)


def test_reversed_history_order_changes_the_actions(
    student: tuple[Path, Callable[[np.ndarray, np.ndarray], np.ndarray]],
    stacked: tuple[Path, Callable[[np.ndarray], np.ndarray]],
) -> None:
    """Feeding the history newest first moves the actions far beyond the 1e-5 parity: the order field matters."""
    rng = np.random.default_rng(2)
    (s_path, s_act), (m_path, m_act) = student, stacked
    s_meta, m_meta = read_policy_metadata(s_path), read_policy_metadata(m_path)
    s_frames = [_frame(s_meta, _raw_terms(s_meta, rng)) for _ in range(STEPS)]
    m_frames = [_frame(m_meta, _raw_terms(m_meta, rng)) for _ in range(STEPS)]
    s_hist, m_hist = _histories(s_meta, s_frames)[-1], _histories(m_meta, m_frames)[-1]
    s_gap = np.abs(s_act(s_frames[-1], s_hist) - s_act(s_frames[-1], s_hist[:, ::-1])).max()
    m_gap = np.abs(m_act(_term_stacked(m_meta, m_hist)) - m_act(_term_stacked(m_meta, m_hist[:, ::-1]))).max()
    assert s_gap > 1e-3 and m_gap > 1e-3, (s_gap, m_gap)


def test_runner_refuses_a_file_without_metadata(tmp_path: Path, students: SimpleNamespace) -> None:
    """A network exported without the gmloco document (as plain torch.onnx.export gives) cannot be run."""
    wrapper = students.good().as_onnx(verbose=False)
    path = tmp_path / "bare.onnx"
    torch.onnx.export(wrapper, wrapper.get_dummy_inputs(), str(path), input_names=["obs", "history"], dynamo=False)
    with pytest.raises(PolicyMetadataError, match="no gmloco policy metadata"):
        OnnxPolicyRunner(path)


def test_runner_refuses_metadata_that_does_not_match_the_inputs(
    tmp_path: Path, student: tuple[Path, object], make_metadata: Callable[..., PolicyMetadata]
) -> None:
    """Metadata claiming 4 history frames on a 6-frame network is refused, not run."""
    path, _ = student
    write_policy_metadata(path, make_metadata(history_length=4))
    with pytest.raises(PolicyMetadataError, match="disagree"):
        OnnxPolicyRunner(path)
