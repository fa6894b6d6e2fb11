# SPDX-License-Identifier: Apache-2.0
"""G1 robot logs in MCAP: schema, writer, damage-tolerant reader, alignment and analyses (``gmloco-logs``)."""

from gmloco.deploy.g1 import G1_FEET, G1_JOINT_NAMES, G1_NUM_JOINTS, joint_index
from gmloco.deploy.logs.align import AlignCfg, AlignedLog, align, resample
from gmloco.deploy.logs.errors import (
    JointOrderError,
    LogContractWarning,
    LogDamageWarning,
    LogFormatError,
    MissingTopicError,
    UnitsError,
)
from gmloco.deploy.logs.mcap_scan import DamageReport
from gmloco.deploy.logs.metadata import RunMetadata, git_commit
from gmloco.deploy.logs.reader import ChannelData, G1Log, ReadCfg, read_log
from gmloco.deploy.logs.schema import SCHEMA_VERSION, TOPICS, UNITS
from gmloco.deploy.logs.writer import G1LogWriter, LogWriterCfg

__all__ = [
    "G1_FEET",
    "G1_JOINT_NAMES",
    "G1_NUM_JOINTS",
    "SCHEMA_VERSION",
    "TOPICS",
    "UNITS",
    "AlignCfg",
    "AlignedLog",
    "ChannelData",
    "DamageReport",
    "G1Log",
    "G1LogWriter",
    "JointOrderError",
    "LogContractWarning",
    "LogDamageWarning",
    "LogFormatError",
    "LogWriterCfg",
    "MissingTopicError",
    "ReadCfg",
    "RunMetadata",
    "UnitsError",
    "align",
    "git_commit",
    "joint_index",
    "read_log",
    "resample",
]
