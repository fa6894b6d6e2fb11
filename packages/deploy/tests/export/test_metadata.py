# SPDX-License-Identifier: Apache-2.0
"""PolicyMetadata: JSON round trip, validation, and reading it back from an ONNX file without torch."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import onnx
import pytest
from onnx import TensorProto, helper

from gmloco.deploy.export import METADATA_FORMAT, PolicyMetadata, read_policy_metadata, write_policy_metadata


def _identity_onnx(path: str) -> None:
    """Write a one-node ONNX model (no torch involved)."""
    x = helper.make_tensor_value_info("x", TensorProto.FLOAT, [1])
    y = helper.make_tensor_value_info("y", TensorProto.FLOAT, [1])
    graph = helper.make_graph([helper.make_node("Identity", ["x"], ["y"])], "g", [x], [y])
    onnx.save(helper.make_model(graph), path)


def test_metadata_round_trips_through_props(make_metadata: Callable[..., PolicyMetadata]) -> None:
    """to_props / from_props restore every field exactly, nested lists and None included."""
    meta = make_metadata()
    props = meta.to_props()
    assert props["format"] == f'"{METADATA_FORMAT}"'
    assert PolicyMetadata.from_props(props) == meta
    assert meta.obs_dim == 5 and meta.num_actions == 2


def test_metadata_validation_rejects_inconsistent_lengths(make_metadata: Callable[..., PolicyMetadata]) -> None:
    """A per-joint list of the wrong length is an error naming the field."""
    with pytest.raises(ValueError, match="joint_damping"):
        make_metadata(joint_damping=[1.0]).validate()
    with pytest.raises(ValueError, match="history_length"):
        make_metadata(history_length=0).validate()


def test_from_props_refuses_foreign_metadata() -> None:
    """mjlab-style props without our format tag are refused, not misread."""
    with pytest.raises(ValueError, match="format"):
        PolicyMetadata.from_props({"joint_names": "a,b"})


def test_write_then_read_from_onnx_replaces_existing_keys(
    tmp_path: Path, make_metadata: Callable[..., PolicyMetadata]
) -> None:
    """Writing twice replaces the entries; reading gives the latest metadata and keeps foreign keys."""
    path = str(tmp_path / "p.onnx")
    _identity_onnx(path)
    model = onnx.load(path)
    model.metadata_props.append(onnx.StringStringEntryProto(key="other", value="kept"))
    onnx.save(model, path)
    write_policy_metadata(path, make_metadata(commit="first"))
    write_policy_metadata(path, make_metadata(commit="second"))
    assert read_policy_metadata(path).commit == "second"
    keys = [p.key for p in onnx.load(path).metadata_props]
    assert keys.count("commit") == 1 and "other" in keys


def test_reading_metadata_does_not_import_torch(tmp_path: Path, make_metadata: Callable[..., PolicyMetadata]) -> None:
    """A fresh interpreter reads the metadata with onnx only; torch and onnxruntime stay unimported."""
    path = str(tmp_path / "p.onnx")
    _identity_onnx(path)
    write_policy_metadata(path, make_metadata())
    code = (
        "import sys; from gmloco.deploy.export import read_policy_metadata; "
        f"m = read_policy_metadata({path!r}); assert m.history_length == 6; "
        "assert 'torch' not in sys.modules and 'onnxruntime' not in sys.modules, 'heavy import'"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
