# SPDX-License-Identifier: Apache-2.0
"""``full_pipeline.py`` with the toy stages registered: the kill/resume test runs this as a subprocess."""

from __future__ import annotations

from tests.pipeline_helpers import toy_registry
from workflows import stage_registry

if __name__ == "__main__":
    stage_registry.STAGES = toy_registry()
    from workflows import full_pipeline

    full_pipeline.main()
