# SPDX-License-Identifier: Apache-2.0
"""Export of the GM-Loco student policy to ONNX with deploy metadata, and its onnxruntime CPU runner.

* :func:`export_policy_onnx`: one ONNX file, inputs ``obs`` ``[batch, obs_dim]`` and ``history``
  ``[batch, N, obs_dim]``, outputs ``actions`` (+ ``latent``, ``eta``); refuses a model whose encoder would be
  dropped (:class:`EncoderDroppedError`) and checks onnxruntime-vs-torch parity. Needs torch (``export`` extra).
* :class:`PolicyMetadata` (schema ``gmloco-policy`` version 2), :func:`read_policy_metadata`: observation terms
  with widths, clip and scale, history length and order, input layout; joints with gains, default pose, action
  scale and effort limits; physics and policy dt; contact model, foot collider, terrain, materials and robot
  randomization trained on; command ranges; commit. Readable with onnx alone; a file without it (or of another
  version) is refused with :class:`PolicyMetadataError`.
* :class:`OnnxPolicyRunner`: builds o_t from raw terms by the metadata, keeps the history buffer and steps the
  policy with onnxruntime (``export`` extra).
* :class:`YawTargetCommand` (:mod:`gmloco.deploy.export.yaw_target`): the heading rule of ``yaw_target`` policies
  (observed w_z = clip(w_z + k * wrap(psi_target - psi))), applied by the runner and by the MPM evaluation.
* ``gmloco-policy-info <policy.onnx>`` (:mod:`gmloco.deploy.export.info`): prints the metadata.

Importing this package needs neither torch nor onnxruntime.
"""

from gmloco.deploy.export.metadata import (
    METADATA_KEY,
    SCHEMA_NAME,
    SCHEMA_VERSION,
    CommandSpec,
    ContactSpec,
    FootColliderSpec,
    JointSpec,
    ObservationSpec,
    ObservationTermSpec,
    PolicyMetadata,
    PolicyMetadataError,
    TimingSpec,
    read_policy_metadata,
    write_policy_metadata,
)
from gmloco.deploy.export.onnx_export import (
    EncoderDroppedError,
    ParityError,
    check_export_keeps_encoder,
    export_policy_onnx,
    verify_parity,
)
from gmloco.deploy.export.runner import OnnxPolicyRunner
from gmloco.deploy.export.yaw_target import YawTargetCfg, YawTargetCommand

__all__ = [
    "METADATA_KEY",
    "SCHEMA_NAME",
    "SCHEMA_VERSION",
    "CommandSpec",
    "ContactSpec",
    "EncoderDroppedError",
    "FootColliderSpec",
    "JointSpec",
    "ObservationSpec",
    "ObservationTermSpec",
    "OnnxPolicyRunner",
    "ParityError",
    "PolicyMetadata",
    "PolicyMetadataError",
    "TimingSpec",
    "YawTargetCfg",
    "YawTargetCommand",
    "check_export_keeps_encoder",
    "export_policy_onnx",
    "read_policy_metadata",
    "verify_parity",
    "write_policy_metadata",
]
