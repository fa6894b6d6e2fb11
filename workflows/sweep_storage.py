# SPDX-License-Identifier: Apache-2.0
"""Where an Optuna sweep keeps its study: ``sweep.storage`` parsed, checked and opened (``docs/sweeps.md``).

* ``""`` (default): the embedded SQLite file ``<run_dir>/study.db``, one worker.
* an RDB URL, ``postgresql+psycopg2://user:password@host:5432/db`` (or ``mysql+<driver>://...``,
  ``sqlite:///<file>``): one study shared by every worker that names it, on any machine.
* ``journal:<file>``: Optuna's journal file, shared by the workers of one machine (or of one shared file system).
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from workflows.stage_runner import PipelineConfigError

__all__ = ["STUDY_DB", "SweepStorage", "parse_storage"]

STUDY_DB = "study.db"
"""File name of the embedded SQLite study in the sweep's run directory."""
JOURNAL_PREFIX = "journal:"
"""Prefix of a journal-file storage."""
RDB_BACKENDS = ("sqlite", "postgresql", "mysql")
"""SQLAlchemy backends Optuna's ``RDBStorage`` supports."""
SCHEMA_ATTEMPTS = 5
"""Tries to open an RDB storage while other workers create its tables."""
KEY = "sweep.storage"
"""The config key parsed here (named in errors)."""


def _bad(message: str) -> PipelineConfigError:
    """An input error naming ``sweep.storage`` (exit code 2)."""
    return PipelineConfigError(KEY, f"{KEY}: {message}")


@dataclass(frozen=True)
class SweepStorage:
    """A parsed ``sweep.storage``."""

    kind: Literal["sqlite", "rdb", "journal"]
    """Embedded or explicit SQLite file, an RDB server, or a journal file."""
    url: str
    """SQLAlchemy URL (``sqlite``, ``rdb``) or the journal file's absolute path (``journal``)."""
    shared: bool
    """Other workers may use the study at the same time (any explicit storage): running trials are theirs."""

    def display(self) -> str:
        """The storage as written to summaries and logs, password hidden."""
        if self.kind == "journal":
            return f"{JOURNAL_PREFIX}{self.url}"
        from sqlalchemy.engine import make_url

        return make_url(self.url).render_as_string(hide_password=True)

    def open(self) -> Any:
        """Return the Optuna storage (``RDBStorage`` or ``JournalStorage``)."""
        import optuna

        if self.kind == "journal":
            from optuna.storages.journal import JournalFileBackend

            Path(self.url).parent.mkdir(parents=True, exist_ok=True)
            return optuna.storages.JournalStorage(JournalFileBackend(self.url))
        if self.kind == "sqlite":
            Path(self.url.removeprefix("sqlite:///")).parent.mkdir(parents=True, exist_ok=True)
            return optuna.storages.RDBStorage(self.url)
        from sqlalchemy.exc import IntegrityError, ProgrammingError

        for attempt in range(SCHEMA_ATTEMPTS):
            try:
                # pool_pre_ping: a worker whose trial trained for hours finds its pooled connection closed.
                return optuna.storages.RDBStorage(self.url, engine_kwargs={"pool_pre_ping": True})
            except (IntegrityError, ProgrammingError):
                # Workers started together race to create Optuna's tables; a retry finds them created.
                if attempt == SCHEMA_ATTEMPTS - 1:
                    raise
                time.sleep(0.5 * (attempt + 1))
        raise AssertionError("unreachable")


def parse_storage(spec: str, run_dir: Path) -> SweepStorage:
    """Parse ``sweep.storage``; raise :class:`PipelineConfigError` (exit code 2) on a malformed or unusable one."""
    spec = spec.strip()
    if not spec:
        return SweepStorage("sqlite", f"sqlite:///{Path(run_dir).resolve() / STUDY_DB}", shared=False)
    if spec.startswith(JOURNAL_PREFIX):
        path = spec.removeprefix(JOURNAL_PREFIX).strip()
        if not path:
            raise _bad(f"'{spec}' names no file; write '{JOURNAL_PREFIX}<path/to/study.journal>'.")
        return SweepStorage("journal", str(Path(path).expanduser().resolve()), shared=True)
    if "://" not in spec:
        raise _bad(
            f"'{spec}' is neither empty (the embedded {STUDY_DB}), an RDB URL "
            f"('postgresql+psycopg2://user@host:5432/db', 'sqlite:///<file>') nor '{JOURNAL_PREFIX}<file>'."
        )
    return _parse_rdb(spec)


def _parse_rdb(spec: str) -> SweepStorage:
    """Parse an RDB URL: known backend, a database named, its driver importable."""
    from sqlalchemy.engine import make_url
    from sqlalchemy.exc import ArgumentError, NoSuchModuleError

    try:
        url = make_url(spec)
    except (ArgumentError, ValueError) as e:
        hidden = re.sub(r"://([^:/@]*):[^@]*@", r"://\1:***@", spec)
        raise _bad(f"'{hidden}' is not a database URL ({e}).") from None
    shown = url.render_as_string(hide_password=True)
    backend = url.get_backend_name()
    if backend not in RDB_BACKENDS:
        raise _bad(f"'{shown}': backend '{backend}' is not one of {', '.join(RDB_BACKENDS)}.")
    if not url.database:
        raise _bad(f"'{shown}' names no database (the part after the last '/').")
    if backend == "sqlite":
        return SweepStorage("sqlite", spec, shared=True)
    try:
        url.get_dialect().import_dbapi()
    except (ImportError, NoSuchModuleError) as e:
        raise _bad(f"'{shown}': the driver '{url.get_driver_name()}' cannot be loaded ({e}).") from None
    return SweepStorage("rdb", spec, shared=True)
