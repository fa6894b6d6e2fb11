# SPDX-License-Identifier: Apache-2.0
"""``sweep.storage`` parsing and checks (``workflows/sweep_storage.py``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from workflows.stage_runner import PipelineConfigError
from workflows.sweep_storage import STUDY_DB, parse_storage


def test_empty_storage_is_the_embedded_sqlite_file_of_the_run_dir(tmp_path: Path) -> None:
    """``""``: ``<run_dir>/study.db``, not shared (a lone worker may requeue running trials)."""
    found = parse_storage("", tmp_path)
    assert found.kind == "sqlite" and not found.shared
    assert found.url == f"sqlite:///{tmp_path.resolve() / STUDY_DB}"


def test_journal_storage_is_an_absolute_shared_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``journal:<file>`` resolves against the working directory and opens as Optuna's journal storage."""
    monkeypatch.chdir(tmp_path)
    found = parse_storage("journal:studies/s.journal", Path("unused"))
    assert found.kind == "journal" and found.shared and found.url == str(tmp_path / "studies" / "s.journal")
    assert found.display() == f"journal:{tmp_path / 'studies' / 's.journal'}"
    assert type(found.open()).__name__ == "JournalStorage" and (tmp_path / "studies").is_dir()


def test_rdb_url_is_shared_and_shown_without_its_password(tmp_path: Path) -> None:
    """A PostgreSQL URL with the locked psycopg2 driver parses; summaries never show the password."""
    found = parse_storage("postgresql+psycopg2://sweeper:s3cret@db.lab:5432/optuna", tmp_path)
    assert found.kind == "rdb" and found.shared
    assert "s3cret" not in found.display() and found.display().endswith("@db.lab:5432/optuna")


def test_explicit_sqlite_url_is_shared(tmp_path: Path) -> None:
    """An explicit ``sqlite:///`` file may be named by several local workers: it counts as shared."""
    found = parse_storage(f"sqlite:///{tmp_path}/all.db", tmp_path)
    assert found.kind == "sqlite" and found.shared


@pytest.mark.parametrize(
    ("spec", "says"),
    [
        ("study.db", "neither empty"),
        ("journal:", "names no file"),
        ("oracle://u@host/db", "backend 'oracle'"),
        ("postgresql+psycopg2://u@host:5432", "names no database"),
        ("postgresql+nosuchdriver://u@host/db", "driver 'nosuchdriver'"),
        ("postgresql+psycopg2://u:pw@host:notaport/db", "not a database URL"),
    ],
)
def test_bad_storage_names_the_key(tmp_path: Path, spec: str, says: str) -> None:
    """Each malformed or unusable storage is one error naming ``sweep.storage`` (exit code 2 at the CLI)."""
    with pytest.raises(PipelineConfigError, match=r"sweep\.storage") as err:
        parse_storage(spec, tmp_path)
    assert says in str(err.value) and ":pw@" not in str(err.value)
