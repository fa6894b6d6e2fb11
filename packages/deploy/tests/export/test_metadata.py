# SPDX-License-Identifier: Apache-2.0
"""PolicyMetadata: JSON round trip, validation, refusal of missing or unknown-version metadata, reading without torch."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import onnx
import pytest
from onnx import TensorProto, helper

from gmloco.deploy.export import (
    METADATA_KEY,
    SCHEMA_VERSION,
    PolicyMetadata,
    PolicyMetadataError,
    read_policy_metadata,
    write_policy_metadata,
)


def _identity_onnx(path: str, props: dict[str, str] | None = None) -> None:
    """Write a one-node ONNX model (no torch involved) with optional metadata props."""
    x = helper.make_tensor_value_info("x", TensorProto.FLOAT, [1])
    y = helper.make_tensor_value_info("y", TensorProto.FLOAT, [1])
    model = helper.make_model(helper.make_graph([helper.make_node("Identity", ["x"], ["y"])], "g", [x], [y]))
    for key, value in (props or {}).items():
        model.metadata_props.append(onnx.StringStringEntryProto(key=key, value=value))
    onnx.save(model, path)


def test_metadata_round_trips_through_props_and_onnx(
    tmp_path: Path, make_metadata: Callable[..., PolicyMetadata]
) -> None:
    """to_props / from_props and write / read restore every nested field exactly, None clips included."""
    meta = make_metadata()
    props = meta.to_props()
    assert list(props) == [METADATA_KEY]
    doc = json.loads(props[METADATA_KEY])
    assert doc["schema_version"] == SCHEMA_VERSION and doc["observation"]["history_order"] == "oldest_first"
    assert PolicyMetadata.from_props(props) == meta
    path = str(tmp_path / "p.onnx")
    _identity_onnx(path)
    write_policy_metadata(path, meta)
    back = read_policy_metadata(path)
    assert back == meta and back.obs_dim == 5 and back.num_actions == 2
    assert back.observation.terms[1].clip is None and back.contact.foot_collider.z_range == [-0.03539, 0.0]


def test_validation_names_the_inconsistent_field(make_metadata: Callable[..., PolicyMetadata]) -> None:
    """Refuse each inconsistency by name.

    Wrong per-joint length, zero history, a history order other than oldest-first, policy_dt != dt * decimation,
    an unknown heading rule, a negative heading stiffness.
    """
    meta = make_metadata()
    with pytest.raises(PolicyMetadataError, match="damping"):
        replace(meta, joints=replace(meta.joints, damping=[1.0])).validate()
    with pytest.raises(PolicyMetadataError, match="history_length 0"):
        make_metadata(history_length=0).validate()
    with pytest.raises(PolicyMetadataError, match="newest_first"):
        replace(meta, observation=replace(meta.observation, history_order="newest_first")).validate()  # type: ignore[arg-type]
    with pytest.raises(PolicyMetadataError, match="policy_dt"):
        replace(meta, timing=replace(meta.timing, decimation=2)).validate()
    with pytest.raises(PolicyMetadataError, match="yaw_command 'heading'"):
        replace(meta, command=replace(meta.command, yaw_command="heading")).validate()
    with pytest.raises(PolicyMetadataError, match="heading_stiffness -1"):
        replace(meta, command=replace(meta.command, heading_stiffness=-1.0)).validate()


def test_from_props_refuses_missing_legacy_and_unknown_versions(make_metadata: Callable[..., PolicyMetadata]) -> None:
    """No document, a version-1 student file, another version, an unknown field: each refused with its reason."""
    with pytest.raises(PolicyMetadataError, match="no gmloco policy metadata"):
        PolicyMetadata.from_props({"joint_names": "a,b"})  # mjlab's own keys only
    with pytest.raises(PolicyMetadataError, match="version-1"):
        PolicyMetadata.from_props({"format": '"gmloco-student-policy/1"', "history_length": "50"})
    doc = make_metadata().to_dict()
    with pytest.raises(PolicyMetadataError, match="version 3"):
        PolicyMetadata.from_props({METADATA_KEY: json.dumps(doc | {"schema_version": 3})})
    doc["timing"]["frame_rate"] = 50.0
    with pytest.raises(PolicyMetadataError, match="frame_rate"):
        PolicyMetadata.from_props({METADATA_KEY: json.dumps(doc)})
    with pytest.raises(PolicyMetadataError, match="JSON"):
        PolicyMetadata.from_props({METADATA_KEY: "{not json"})


def test_write_replaces_the_document_and_keeps_foreign_keys(
    tmp_path: Path, make_metadata: Callable[..., PolicyMetadata]
) -> None:
    """Writing twice leaves one document (the latest); mjlab's keys written by others stay."""
    path = str(tmp_path / "p.onnx")
    _identity_onnx(path, {"joint_names": "a,b"})
    write_policy_metadata(path, make_metadata(commit="first"))
    write_policy_metadata(path, make_metadata(commit="second"))
    assert read_policy_metadata(path).commit == "second"
    keys = [p.key for p in onnx.load(path).metadata_props]
    assert keys.count(METADATA_KEY) == 1 and "joint_names" in keys
    assert not list(tmp_path.glob(".*tmp"))  # the atomic write left no temporary file


def test_reading_metadata_does_not_import_torch(tmp_path: Path, make_metadata: Callable[..., PolicyMetadata]) -> None:
    """A fresh interpreter reads the metadata with onnx only; torch and onnxruntime stay unimported."""
    path = str(tmp_path / "p.onnx")
    _identity_onnx(path)
    write_policy_metadata(path, make_metadata())
    code = (
        "import sys; from gmloco.deploy.export import read_policy_metadata; "
        f"m = read_policy_metadata({path!r}); assert m.observation.history_length == 6; "
        "assert 'torch' not in sys.modules and 'onnxruntime' not in sys.modules, 'heavy import'"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
