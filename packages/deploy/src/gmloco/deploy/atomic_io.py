# SPDX-License-Identifier: Apache-2.0
"""Atomic file writes: a temporary file in the target's folder, then ``os.replace`` (a kill never leaves half a file).

Standard library only, so every package that depends on ``gmloco-deploy`` may use it without pulling in Warp,
MuJoCo or torch.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

__all__ = ["atomic_write", "atomic_write_json"]


def atomic_write(path: str | os.PathLike[str], write: Callable[[IO[bytes]], Any]) -> Path:
    """Call ``write`` on a binary handle of a temporary file beside ``path``, then rename it to ``path``.

    The folder is created if needed; the file is readable by all (0644); on any error the temporary file is removed
    and ``path`` keeps what it held before.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def atomic_write_json(
    path: str | os.PathLike[str], obj: Any, *, indent: int = 1, allow_nan: bool = True, newline: bool = False
) -> Path:
    """Write ``obj`` as JSON to ``path`` atomically (``allow_nan=False``: strict JSON; ``newline``: a final newline)."""
    text = json.dumps(obj, indent=indent, allow_nan=allow_nan) + ("\n" if newline else "")
    return atomic_write(path, lambda fh: fh.write(text.encode()))
