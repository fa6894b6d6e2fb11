# SPDX-License-Identifier: Apache-2.0
"""Read and write a fitted ``RftExtensionsCfg`` as JSON (atomic), with the provenance of its fit."""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import asdict, fields
from pathlib import Path
from typing import Any

from gmloco.contact.config import RftExtensionsCfg

__all__ = ["load_rft_extensions", "save_rft_extensions"]


def save_rft_extensions(ext: RftExtensionsCfg, path: str | Path, provenance: dict[str, Any]) -> Path:
    """Write ``{"extensions": ..., "provenance": ...}`` to ``path`` atomically (temporary file, then rename; 0644)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".json.tmp")
    try:
        with os.fdopen(fd, "w") as fh:
            json.dump({"extensions": asdict(ext), "provenance": provenance}, fh, indent=1)
        os.chmod(tmp, 0o644)  # readable by all, as any other result file (mkstemp makes it 0600)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def load_rft_extensions(path: str | Path) -> RftExtensionsCfg:
    """Return the ``RftExtensionsCfg`` of a file written by :func:`save_rft_extensions` (validated on build)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(
            f"{path}: no fitted RFT extensions; fit them with python -m gmloco.eval.calibration.fit_cli --write-default"
        )
    data = json.loads(path.read_text())["extensions"]
    known = {f.name for f in fields(RftExtensionsCfg)}
    unknown = set(data) - known
    if unknown:
        raise ValueError(f"{path}: unknown RftExtensionsCfg fields {sorted(unknown)}")
    return RftExtensionsCfg(**data)
