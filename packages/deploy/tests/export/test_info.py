# SPDX-License-Identifier: Apache-2.0
"""gmloco-policy-info: readable metadata, the JSON document, and exit 2 with a reason on bad input."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import onnx
import pytest
from onnx import TensorProto, helper

from gmloco.deploy.export import PolicyMetadata, write_policy_metadata
from gmloco.deploy.export.info import main


def _model(path: Path) -> Path:
    """A one-node ONNX model without metadata."""
    x = helper.make_tensor_value_info("x", TensorProto.FLOAT, [1])
    y = helper.make_tensor_value_info("y", TensorProto.FLOAT, [1])
    onnx.save(helper.make_model(helper.make_graph([helper.make_node("Identity", ["x"], ["y"])], "g", [x], [y])), path)
    return path


def test_info_prints_terms_history_order_collider_and_effort(
    tmp_path: Path, make_metadata: Callable[..., PolicyMetadata], capsys: pytest.CaptureFixture[str]
) -> None:
    """Text: terms in frame order with their slices, oldest-first history, collider, effort; --json: the document."""
    path = _model(tmp_path / "p.onnx")
    write_policy_metadata(path, make_metadata())
    assert main([str(path)]) == 0
    text = capsys.readouterr().out
    assert "history 6 frames oldest_first" in text and "[0:2]" in text and "[2:5]" in text
    assert "foot collider on left_foot, right_foot" in text and "139.0" in text and "rft3d" in text
    assert main([str(path), "--json"]) == 0
    assert PolicyMetadata.from_dict(json.loads(capsys.readouterr().out)) == make_metadata()


@pytest.mark.parametrize("case", ["missing", "not_onnx", "no_metadata"])
def test_info_exits_2_with_a_reason(tmp_path: Path, case: str, capsys: pytest.CaptureFixture[str]) -> None:
    """A missing file, a file that is not ONNX, and an ONNX file without metadata: exit 2, one line saying why."""
    path = tmp_path / "p.onnx"
    if case == "not_onnx":
        path.write_text("not a model")
    elif case == "no_metadata":
        _model(path)
    assert main([str(path)]) == 2
    err = capsys.readouterr().err
    reason = {"missing": "does not exist", "not_onnx": "not a readable ONNX", "no_metadata": "no gmloco policy"}[case]
    assert reason in err and "Traceback" not in err
