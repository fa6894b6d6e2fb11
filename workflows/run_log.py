# SPDX-License-Identifier: Apache-2.0
"""Send library output (mjlab tables, Warp cache lines, rsl-rl iteration logs, warnings) to the run's log file.

While stages run, file descriptors 1 and 2 and ``sys.stdout`` / ``sys.stderr`` point at the log file, so Python
prints, ``warnings``, ``logging`` records and C-level output of Warp, MuJoCo and subprocesses all land there; the pipeline's console
(:data:`pipeline_report.console`) keeps writing to the terminal through a copy of the original stderr.
"""

from __future__ import annotations

import io
import logging
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from rich.console import Console

__all__ = ["job_log_path", "library_output_to"]


def job_log_path(run_dir: Path) -> Path:
    """Hydra's job log in ``run_dir`` (``<job name>.log``) inside a Hydra run, else ``run_dir/pipeline.log``."""
    from hydra.core.hydra_config import HydraConfig

    if HydraConfig.initialized():
        return run_dir / f"{HydraConfig.get().job.name}.log"
    return run_dir / "pipeline.log"


def _fd_backed(stream: object) -> bool:
    """Whether ``stream`` writes to file descriptor 2 (False for pytest's and other in-memory captures)."""
    try:
        return stream.fileno() == 2  # type: ignore[attr-defined]
    except (AttributeError, OSError, io.UnsupportedOperation):
        return False


def _console_handlers() -> list[logging.Handler]:
    """Root handlers that write to stdout/stderr (Hydra's console handler); its file handler already logs."""
    return [
        h
        for h in logging.getLogger().handlers
        if type(h) is logging.StreamHandler and getattr(h, "stream", None) in (sys.stdout, sys.stderr)
    ]


@contextmanager
def library_output_to(log_path: Path, console: Console) -> Iterator[None]:
    """Send fds 1 and 2, ``sys.stdout`` and ``sys.stderr`` to ``log_path`` (appending); keep ``console`` on stderr.

    ``console`` writes to a copy of the original fd 2 when ``sys.stderr`` is that descriptor, else to the original
    ``sys.stderr`` object (an in-memory capture, as under pytest).
    """
    log_path.parent.mkdir(parents=True, exist_ok=True)
    streams = (sys.stdout, sys.stderr)
    for stream in streams:
        stream.flush()
    saved = {fd: os.dup(fd) for fd in (1, 2)}
    log_fd = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    owned = _fd_backed(sys.stderr)
    terminal = os.fdopen(os.dup(saved[2]), "w", buffering=1, encoding="utf-8") if owned else sys.stderr
    log_text = os.fdopen(os.dup(log_fd), "w", buffering=1, encoding="utf-8", errors="replace")
    handlers = _console_handlers()
    root = logging.getLogger()
    try:
        for fd in (1, 2):
            os.dup2(log_fd, fd)
        for h in handlers:
            root.removeHandler(h)
        console.file = terminal
        sys.stdout = sys.stderr = log_text
        yield
    finally:
        log_text.flush()
        sys.stdout, sys.stderr = streams
        for fd, copy in saved.items():
            os.dup2(copy, fd)
            os.close(copy)
        os.close(log_fd)
        log_text.close()
        for h in handlers:
            root.addHandler(h)
        console.file = None  # type: ignore[assignment]  # back to sys.stderr at each write
        if owned:
            terminal.close()
