# SPDX-License-Identifier: Apache-2.0
"""Shared fixtures: Warp on the CPU device, optional shared kernel cache (WARP_CACHE_PATH)."""

from __future__ import annotations

import os

import pytest
import warp as wp

wp.config.quiet = True
if os.environ.get("WARP_CACHE_PATH"):
    wp.config.kernel_cache_dir = os.environ["WARP_CACHE_PATH"]

DEVICE = "cpu"


@pytest.fixture(scope="session")
def device() -> str:
    """Warp device used by the kernel tests."""
    wp.init()
    return DEVICE
