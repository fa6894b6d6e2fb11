# SPDX-License-Identifier: Apache-2.0
"""Run a workflow script with the project's Python when the one that started it lacks the dependencies.

``python workflows/full_pipeline.py`` started by a Python without Hydra or the gmloco packages (a system Python,
no ``uv run``, no ``PYTHONPATH``) re-runs itself with the checkout's ``.venv`` Python when ``uv sync`` made one,
and otherwise stops with exit code 2 and the exact command to run. Standard library only: it runs before any
dependency is imported.
"""

from __future__ import annotations

import importlib.util
import os
import shlex
import sys
from collections.abc import Sequence
from pathlib import Path

__all__ = ["REQUIRED_MODULES", "VENV_DIR", "ensure_project_python"]

REPO_ROOT = Path(__file__).resolve().parents[1]
"""Checkout root."""
VENV_DIR = REPO_ROOT / ".venv"
"""The environment ``uv sync`` / ``uv run`` creates."""
REQUIRED_MODULES = ("hydra", "omegaconf", "gmloco.deploy", "gmloco.train")
"""Modules the workflows import."""
_REEXEC_ENV = "GMLOCO_PROJECT_PYTHON"
"""Set on the re-run, so that a broken environment cannot loop."""


def _missing(modules: Sequence[str]) -> list[str]:
    """Modules of ``modules`` this Python cannot import."""
    out = []
    for name in modules:
        try:
            found = importlib.util.find_spec(name) is not None
        except ModuleNotFoundError:  # a parent package is missing
            found = False
        if not found:
            out.append(name)
    return out


def ensure_project_python(
    script: str, venv: Path = VENV_DIR, modules: Sequence[str] = REQUIRED_MODULES, argv: Sequence[str] | None = None
) -> None:
    """Return when this Python has ``modules``; else re-run ``script`` with ``venv``'s Python, or exit 2 saying how.

    Args:
        script: path of the running workflow script.
        venv: the project's virtual environment.
        modules: modules the script needs.
        argv: the script's arguments (default: ``sys.argv[1:]``).
    """
    missing = _missing(modules)
    if not missing:
        return
    args = list(sys.argv[1:] if argv is None else argv)
    python = venv / "bin" / "python"
    if python.is_file() and Path(sys.prefix).resolve() != venv.resolve() and not os.environ.get(_REEXEC_ENV):
        print(f"note: {sys.executable} lacks {', '.join(missing)}; running with {python}", file=sys.stderr)
        os.execve(python, [str(python), script, *args], {**os.environ, _REEXEC_ENV: "1"})
    rel = os.path.relpath(Path(script).resolve(), REPO_ROOT)
    command = shlex.join(["python3", "-m", "uv", "run", "python", rel, *args])
    print(
        f"error: this Python ({sys.executable}) cannot import {', '.join(missing)}, which gmloco's workflows need, "
        f"and {venv} holds no environment to use instead. From {REPO_ROOT} run: {command} (uv creates .venv with "
        "every dependency on its first run; without uv: python3 -m pip install uv). Nothing was run.",
        file=sys.stderr,
    )
    raise SystemExit(2)
