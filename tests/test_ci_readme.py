# SPDX-License-Identifier: Apache-2.0
"""The README's two command lines are exactly what ``.ci/run`` runs."""

from __future__ import annotations

import os
import re
import subprocess

from tests.pipeline_helpers import REPO_ROOT

CI = REPO_ROOT / ".ci" / "run"


def _readme_commands() -> list[str]:
    """Command lines in the README's ``ci:commands`` block."""
    text = (REPO_ROOT / "README.md").read_text(encoding="utf-8")
    block = re.search(r"<!-- ci:commands.*?-->(.*?)<!-- /ci:commands -->", text, re.S)
    assert block, "README.md lost its ci:commands block"
    return [line for line in block.group(1).splitlines() if line.startswith("python3 ")]


def test_readme_has_exactly_two_bootstrapping_commands() -> None:
    """Main job first, tests second; both bootstrap uv with pip so a machine without uv can run them."""
    main, tests = _readme_commands()
    for line in (main, tests):
        assert line.startswith("python3 -m pip install -q uv==")
    assert main.endswith("workflows/full_pipeline.py +exp=gm_loco")
    assert tests.endswith("uv run pytest")


def test_ci_runs_the_readme_commands_verbatim() -> None:
    """``.ci/run --print-commands`` prints the README lines, and the script runs them and the quality gates."""
    assert os.access(CI, os.X_OK)
    res = subprocess.run([str(CI), "--print-commands"], capture_output=True, text=True, check=True, cwd=REPO_ROOT)
    assert res.stdout.splitlines() == _readme_commands()
    script = CI.read_text(encoding="utf-8")
    for needle in ('bash -c "$TEST_CMD"', 'bash -c "$MAIN_CMD"', "WARP_CACHE_PATH", "ruff format --check", "pyright"):
        assert needle in script
