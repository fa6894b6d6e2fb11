# SPDX-License-Identifier: Apache-2.0
"""``python workflows/full_pipeline.py`` from a Python without the dependencies: re-run with .venv, or say how."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.pipeline_helpers import REPO_ROOT
from workflows.project_python import VENV_DIR, ensure_project_python


def test_missing_dependencies_without_a_venv_exit_2_with_the_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """No usable .venv: exit 2 and one paragraph holding the exact ``uv run`` command with the user's arguments."""
    script = str(REPO_ROOT / "workflows" / "full_pipeline.py")
    with pytest.raises(SystemExit) as info:
        ensure_project_python(script, tmp_path / ".venv", ("no_such_module_for_gmloco",), ["+exp=gm_loco", "seed=3"])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert "python3 -m uv run python workflows/full_pipeline.py +exp=gm_loco seed=3" in err
    assert "no_such_module_for_gmloco" in err and err.count("\n") == 1


def test_present_dependencies_return_at_once() -> None:
    """With the dependencies importable (this test's own Python) nothing happens."""
    ensure_project_python("unused.py", modules=("omegaconf",))


@pytest.mark.skipif(not (VENV_DIR / "bin" / "python").is_file(), reason="needs the checkout's .venv (uv sync)")
def test_plain_python_without_the_dependencies_reruns_with_the_venv(tmp_path: Path) -> None:
    """The base interpreter without site-packages or PYTHONPATH (``python -S``) runs ``--cfg job`` through .venv."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    base = Path(sys.base_prefix) / "bin" / f"python{sys.version_info.major}.{sys.version_info.minor}"
    cmd = [str(base), "-S", "workflows/full_pipeline.py", "+exp=gm_loco", "+scale=smoke", "--cfg", "job"]
    res = subprocess.run(cmd, cwd=REPO_ROOT, env=env, capture_output=True, text=True, timeout=300, check=False)
    assert res.returncode == 0, res.stderr[-3000:]
    assert "running with" in res.stderr and "exp_name: gm_loco" in res.stdout
