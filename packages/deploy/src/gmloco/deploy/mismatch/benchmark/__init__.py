# SPDX-License-Identifier: Apache-2.0
"""Concealed-effect benchmark: truth generator (independent injection), episode sweep, scorer."""

__all__: list[str] = []
