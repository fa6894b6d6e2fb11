# SPDX-License-Identifier: Apache-2.0
"""ONNX export: parity with torch (history input included), refusal of dropped encoders, metadata checks."""

from __future__ import annotations

import copy
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

torch = pytest.importorskip("torch")
pytest.importorskip("onnxruntime")

from gmloco.deploy.export import (  # noqa: E402
    EncoderDroppedError,
    ParityError,
    PolicyMetadata,
    export_policy_onnx,
    read_policy_metadata,
    verify_parity,
)


def test_export_matches_torch_including_the_history_input(
    tmp_path: Path, students: SimpleNamespace, make_metadata: Callable[..., PolicyMetadata], dims: SimpleNamespace
) -> None:
    """Onnxruntime reproduces all three outputs to <= 1e-5, and the history changes the action."""
    import onnxruntime as ort

    model = students.good()
    path = export_policy_onnx(model, tmp_path / "student.onnx", make_metadata())
    wrapper = model.as_onnx(verbose=False)
    assert verify_parity(wrapper, path, atol=1e-5) <= 1e-5
    drifted = copy.deepcopy(wrapper)
    with torch.no_grad():
        next(drifted.parameters()).add_(1e-2)  # a torch model that no longer matches the export
    with pytest.raises(ParityError, match="max abs difference"):
        verify_parity(drifted, path, atol=1e-5)
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    assert [i.name for i in session.get_inputs()] == ["obs", "history"]
    assert [o.name for o in session.get_outputs()] == ["actions", "latent", "eta"]
    gen = torch.Generator().manual_seed(1)
    obs = torch.randn(3, dims.obs_dim, generator=gen)
    h1, h2 = torch.randn(2, 3, dims.history, dims.obs_dim, generator=gen)
    a1 = session.run(["actions"], {"obs": obs.numpy(), "history": h1.numpy()})[0]
    a2 = session.run(["actions"], {"obs": obs.numpy(), "history": h2.numpy()})[0]
    with torch.no_grad():
        np.testing.assert_allclose(a1, wrapper(obs, h1)[0].numpy(), atol=1e-5)
    assert np.abs(a1 - a2).max() > 1e-3  # the history really feeds the action
    assert read_policy_metadata(path) == make_metadata()


def test_export_refuses_a_stock_export_that_drops_the_encoder(
    tmp_path: Path, students: SimpleNamespace, make_metadata: Callable[..., PolicyMetadata]
) -> None:
    """An obs-only wrapper (rsl-rl's stock as_onnx) is refused before any file is written."""
    with pytest.raises(EncoderDroppedError, match="history encoder"):
        export_policy_onnx(students.stock(), tmp_path / "x.onnx", make_metadata())
    assert not (tmp_path / "x.onnx").exists()


def test_export_refuses_a_wrapper_without_encoder_weights(
    tmp_path: Path, students: SimpleNamespace, make_metadata: Callable[..., PolicyMetadata]
) -> None:
    """A wrapper that takes history but holds fewer weights than the policy names the missing module."""
    with pytest.raises(EncoderDroppedError, match="encoder"):
        export_policy_onnx(students.silent(), tmp_path / "x.onnx", make_metadata())


def test_export_refuses_metadata_that_disagrees_with_the_inputs(
    tmp_path: Path, students: SimpleNamespace, make_metadata: Callable[..., PolicyMetadata]
) -> None:
    """A history length in the metadata different from the model's input is a ValueError."""
    with pytest.raises(ValueError, match="history_length"):
        export_policy_onnx(students.good(), tmp_path / "x.onnx", make_metadata(history_length=4))
