# SPDX-License-Identifier: Apache-2.0
"""Run-directory helpers that know nothing about Hydra: atomic writes, seeding, git state, layout.

Packages must not import ``workflows``; they get plain paths and dicts from the stage wrappers. Everything
written into a run directory goes through :func:`atomic_write_bytes`, so a killed process leaves either the
old file or the new one, never a torn one.
"""

from __future__ import annotations

import hashlib
import json
import os
import random
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = [
    "RunDir",
    "atomic_save_torch",
    "atomic_write_bytes",
    "atomic_write_json",
    "atomic_write_text",
    "atomic_write_yaml",
    "config_hash",
    "list_outputs",
    "read_json",
    "seed_everything",
    "write_git_state",
]


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder and ``os.replace``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def atomic_write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_json(path: str | os.PathLike[str], obj: Any) -> Path:
    """Write ``obj`` as indented, key-sorted JSON atomically."""
    return atomic_write_text(path, json.dumps(obj, indent=2, sort_keys=True, default=str) + "\n")


def atomic_write_yaml(path: str | os.PathLike[str], obj: Any) -> Path:
    """Write a plain container (or an OmegaConf node) as YAML atomically."""
    from omegaconf import OmegaConf

    return atomic_write_text(path, OmegaConf.to_yaml(OmegaConf.create(obj)))


def atomic_save_torch(path: str | os.PathLike[str], obj: Any) -> Path:
    """Save a checkpoint with ``torch.save`` atomically (torch is imported lazily)."""
    import io

    import torch

    buf = io.BytesIO()
    torch.save(obj, buf)
    return atomic_write_bytes(path, buf.getvalue())


def read_json(path: str | os.PathLike[str], default: Any = None) -> Any:
    """Return the parsed JSON at ``path``, or ``default`` when the file does not exist."""
    path = Path(path)
    if not path.exists():
        return default
    return json.loads(path.read_text(encoding="utf-8"))


def config_hash(obj: Any) -> str:
    """Return a short, stable SHA-256 of a JSON-serializable object (keys sorted)."""
    blob = json.dumps(obj, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(blob.encode("utf-8")).hexdigest()[:16]


def seed_everything(seed: int) -> None:
    """Seed Python, NumPy and (when installed) torch; call it first in every workflow."""
    random.seed(seed)
    os.environ["PYTHONHASHSEED"] = str(seed)
    try:
        import numpy as np

        np.random.seed(seed)  # noqa: NPY002  (seeds libraries that still use the legacy global RNG)
    except ImportError:  # numpy is optional for the workflow layer
        pass
    try:
        import torch

        torch.manual_seed(seed)
    except ImportError:
        pass


def list_outputs(folder: str | os.PathLike[str]) -> dict[str, int]:
    """Map every file under ``folder`` (relative POSIX path) to its size in bytes; temp files are skipped."""
    folder = Path(folder)
    if not folder.is_dir():
        return {}
    out: dict[str, int] = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file() and not p.name.endswith(".tmp"):
            out[p.relative_to(folder).as_posix()] = p.stat().st_size
    return out


def _git(repo: Path, *args: str) -> str:
    """Run one git command in ``repo`` and return its stdout ('' on any failure)."""
    try:
        res = subprocess.run(["git", *args], cwd=repo, capture_output=True, text=True, timeout=30, check=False)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    return res.stdout if res.returncode == 0 else ""


def write_git_state(repo: str | os.PathLike[str], dest_dir: str | os.PathLike[str]) -> dict[str, Any]:
    """Save commit, status and diff of ``repo`` as ``git/gmloco-<commit>-<diff>.diff`` (rsl_rl's format).

    Returns:
        ``{"commit", "dirty", "diff_file"}``; ``commit`` is ``None`` outside a git checkout.
    """
    repo = Path(repo)
    commit = _git(repo, "rev-parse", "HEAD").strip() or None
    status = _git(repo, "status", "--short")
    diff = _git(repo, "diff", "HEAD") if commit else ""
    text = f"--- git commit ---\n{commit}\n--- git status ---\n{status}\n--- git diff ---\n{diff}"
    name = f"gmloco-{(commit or 'nogit')[:8]}-{config_hash(text)[:8]}.diff"
    atomic_write_text(Path(dest_dir) / "git" / name, text)
    return {"commit": commit, "dirty": bool(status.strip()), "diff_file": f"git/{name}"}


@dataclass(frozen=True)
class RunDir:
    """Layout of one run directory: ``<root>/{config.yaml, manifest.json, summary.json, summary.md, git/, tb/, <stage>/}``."""

    root: Path
    """Absolute path of the run directory."""

    @property
    def config_yaml(self) -> Path:
        """Resolved configuration of the latest invocation."""
        return self.root / "config.yaml"

    @property
    def manifest_json(self) -> Path:
        """Stage statuses, config hashes, outputs and timings."""
        return self.root / "manifest.json"

    @property
    def summary_json(self) -> Path:
        """Summary of the latest invocation: every stage's status and metrics."""
        return self.root / "summary.json"

    @property
    def summary_md(self) -> Path:
        """What each stage produced and its key numbers, for a reader."""
        return self.root / "summary.md"

    @property
    def tensorboard_dir(self) -> Path:
        """TensorBoard event files of the pipeline (stages may add their own under their folder)."""
        return self.root / "tb"

    def stage_dir(self, stage: str) -> Path:
        """Default output folder of ``stage``."""
        return self.root / stage
