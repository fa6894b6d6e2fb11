# SPDX-License-Identifier: Apache-2.0
"""The package graph of ``docs/architecture.md``: each import between packages is declared, none goes upward."""

from __future__ import annotations

import ast
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("contact", "deploy", "train", "eval")


def _imported_packages(package: str) -> set[str]:
    """Return the other ``gmloco`` packages (and ``workflows``) that ``package``'s sources import, anywhere."""
    found: set[str] = set()
    for path in (ROOT / "packages" / package / "src").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            for name in names:
                parts = name.split(".")
                if parts[0] == "workflows" or (parts[0] == "gmloco" and len(parts) > 1 and parts[1] != package):
                    found.add(parts[0] if parts[0] == "workflows" else parts[1])
    return found


def _declared_packages(package: str) -> set[str]:
    """Return the ``gmloco-*`` distributions ``package``'s pyproject.toml requires, its extras included."""
    project = tomllib.loads((ROOT / "packages" / package / "pyproject.toml").read_text())["project"]
    specs = list(project.get("dependencies", []))
    for extra in project.get("optional-dependencies", {}).values():
        specs += extra
    names = (re.match(r"[A-Za-z0-9_.-]+", spec) for spec in specs)
    return {m.group(0).removeprefix("gmloco-") for m in names if m and m.group(0).startswith("gmloco-")}


def test_every_import_between_packages_is_declared() -> None:
    """A package that imports ``gmloco.<other>`` lists ``gmloco-<other>`` in its dependencies or an extra."""
    for package in PACKAGES:
        missing = _imported_packages(package) - _declared_packages(package) - {"workflows"}
        assert not missing, f"gmloco-{package} imports {sorted(missing)} without declaring them"


def test_no_package_imports_train_or_workflows() -> None:
    """Training and the workflows sit on top: no package imports them."""
    for package in PACKAGES:
        assert not _imported_packages(package) & {"train", "workflows"} - {package}, package
