# SPDX-License-Identifier: Apache-2.0
"""Repository-wide pytest options: ``slow`` tests run only with ``--runslow``, ``gpu`` tests only with CUDA.

Package ``conftest.py`` files must not register ``--runslow`` again (pytest refuses duplicate options).
"""

from __future__ import annotations

import functools

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    """Register ``--runslow``."""
    parser.addoption("--runslow", action="store_true", default=False, help="also run tests marked slow")


@functools.cache
def _cuda_available() -> bool:
    """``torch.cuda.is_available()``, imported only when a ``gpu`` test was collected."""
    try:
        import torch
    except ImportError:
        return False
    return bool(torch.cuda.is_available())


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Skip ``slow`` tests without ``--runslow`` and ``gpu`` tests without a CUDA device, with a reason."""
    skip_slow = pytest.mark.skip(reason="slow: run with --runslow")
    skip_gpu = pytest.mark.skip(reason="gpu: no CUDA device")
    for item in items:
        if "slow" in item.keywords and not config.getoption("--runslow"):
            item.add_marker(skip_slow)
        if "gpu" in item.keywords and not _cuda_available():
            item.add_marker(skip_gpu)
