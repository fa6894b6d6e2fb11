# SPDX-License-Identifier: Apache-2.0
"""Errors and warnings raised on bad robot logs; each message names the problem and what to do."""

from __future__ import annotations

__all__ = [
    "JointOrderError",
    "LogContractWarning",
    "LogDamageWarning",
    "LogFormatError",
    "MissingTopicError",
    "UnitsError",
]


class LogFormatError(ValueError):
    """The file is not a readable G1 log (not MCAP, no run metadata, malformed fields)."""


class MissingTopicError(LogFormatError):
    """A required topic has no messages."""


class JointOrderError(LogFormatError):
    """Joint names are unknown, missing, duplicated, or the joint count is wrong."""


class UnitsError(LogFormatError):
    """The file declares units that differ from the schema."""


class LogDamageWarning(UserWarning):
    """The file is damaged (truncated or corrupted); it was read up to, or around, the damage."""


class LogContractWarning(UserWarning):
    """The data violate a soft contract (non-monotonic time, implausible magnitudes, dropped samples)."""
