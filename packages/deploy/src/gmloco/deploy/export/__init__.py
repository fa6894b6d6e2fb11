# SPDX-License-Identifier: Apache-2.0
"""Export of the GM-Loco student policy to ONNX with deploy metadata, and its onnxruntime CPU runner.

* :func:`export_policy_onnx`: one ONNX file, inputs ``obs`` ``[batch, obs_dim]`` and ``history``
  ``[batch, N, obs_dim]``, outputs ``actions`` (+ ``latent``, ``eta``); refuses a model whose encoder would be
  dropped (:class:`EncoderDroppedError`) and checks onnxruntime-vs-torch parity. Needs torch (``export`` extra).
* :class:`PolicyMetadata`, :func:`read_policy_metadata`: joints, gains, default pose, action scale, observation
  layout and scaling, history length, policy dt, commit; readable with onnx alone.
* :class:`OnnxPolicyRunner`: keeps the history buffer and steps the policy with onnxruntime (``export`` extra).

Importing this package needs neither torch nor onnxruntime.
"""

from gmloco.deploy.export.metadata import (
    METADATA_FORMAT,
    PolicyMetadata,
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

__all__ = [
    "METADATA_FORMAT",
    "EncoderDroppedError",
    "OnnxPolicyRunner",
    "ParityError",
    "PolicyMetadata",
    "check_export_keeps_encoder",
    "export_policy_onnx",
    "read_policy_metadata",
    "verify_parity",
    "write_policy_metadata",
]
