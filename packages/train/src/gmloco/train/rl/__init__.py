# SPDX-License-Identifier: Apache-2.0
"""RL plumbing on top of mjlab / rsl-rl: runner and ONNX export."""

from gmloco.train.rl.export import export_policy_onnx, policy_metadata
from gmloco.train.rl.runner import GmlocoOnPolicyRunner, latest_checkpoint

__all__ = ["GmlocoOnPolicyRunner", "export_policy_onnx", "latest_checkpoint", "policy_metadata"]
