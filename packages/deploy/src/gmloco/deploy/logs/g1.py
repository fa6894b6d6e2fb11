# SPDX-License-Identifier: Apache-2.0
"""The G1 joint vocabulary of the log schema, as defined once in :mod:`gmloco.deploy.g1`."""

from __future__ import annotations

from gmloco.deploy.g1 import (
    G1_FEET,
    G1_JOINT_NAMES,
    G1_LEG_JOINTS,
    G1_NUM_JOINTS,
    G1_NUM_MOTOR_SLOTS,
    joint_index,
)

__all__ = [
    "G1_FEET",
    "G1_JOINT_NAMES",
    "G1_LEG_JOINTS",
    "G1_NUM_JOINTS",
    "G1_NUM_MOTOR_SLOTS",
    "joint_index",
]
