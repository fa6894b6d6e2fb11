# SPDX-License-Identifier: Apache-2.0
"""Several sweep workers share one study on a real PostgreSQL server (``sweep.storage=postgresql+psycopg2://``).

The server (``initdb`` / ``pg_ctl`` of the PostgreSQL binaries on ``PATH``; as root, run as the ``postgres``
user) lives in a temporary folder on a free port for this test only. The workers are three processes of the
sweep's command, ``tests/workflows/sweep_fake_worker.py``: the same Hydra entry, study, trial folders, chunked
reports and median pruner as ``workflows/sweep.py``, with the training replaced by a cheap deterministic function
(real trials take minutes each on this CPU).
"""

from __future__ import annotations

import json
import os
import pwd
import shutil
import socket
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.pipeline_helpers import REPO_ROOT, plain_python_env

pytestmark = pytest.mark.slow

PG_BINARIES = ("postgres", "initdb", "pg_ctl")
"""Server programs the test needs."""
N_WORKERS = 3
"""Worker processes started at once."""
N_TRIALS = 6
"""Finished trials the study should hold."""


def _as_server_user() -> list[str]:
    """Command prefix that runs the server's programs as a non-root user (PostgreSQL refuses root)."""
    if os.geteuid() != 0:
        return []
    try:
        pwd.getpwnam("postgres")
    except KeyError:
        pytest.skip("running as root and there is no 'postgres' user to run the PostgreSQL server as")
    if shutil.which("runuser") is None:
        pytest.skip("running as root without 'runuser' to start the PostgreSQL server as 'postgres'")
    return ["runuser", "-u", "postgres", "--"]


def _free_port() -> int:
    """A TCP port nothing listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture
def postgres_url() -> Iterator[str]:
    """Start a PostgreSQL server with an empty database ``gmloco_sweep``; yield its URL; stop the server."""
    missing = [b for b in PG_BINARIES if shutil.which(b) is None]
    if missing:
        pytest.skip(f"PostgreSQL binaries not on PATH: {', '.join(missing)} (Debian: apt install postgresql)")
    prefix = _as_server_user()
    base = Path(tempfile.mkdtemp(prefix="gmloco-pg-"))
    if prefix:
        shutil.chown(base, user="postgres")
    data, port = base / "data", _free_port()

    def run(*args: str) -> None:
        """Run one of the server's programs (as its user); raise when it fails."""
        subprocess.run([*prefix, *args], check=True, capture_output=True, text=True, timeout=120)

    run("initdb", "-D", str(data), "-U", "gmloco", "--auth=trust", "-E", "UTF8")
    options = f"-p {port} -k {base} -c listen_addresses=127.0.0.1"
    run("pg_ctl", "-D", str(data), "-l", str(base / "server.log"), "-w", "-o", options, "start")
    try:
        import psycopg2

        conn = psycopg2.connect(host="127.0.0.1", port=port, user="gmloco", dbname="postgres")
        conn.autocommit = True
        conn.cursor().execute("CREATE DATABASE gmloco_sweep")
        conn.close()
        yield f"postgresql+psycopg2://gmloco@127.0.0.1:{port}/gmloco_sweep"
    finally:
        run("pg_ctl", "-D", str(data), "-w", "-m", "fast", "stop")
        shutil.rmtree(base, ignore_errors=True)


def test_three_workers_share_one_study_on_postgresql(postgres_url: str, tmp_path: Path) -> None:
    """Three workers started with the same command fill one study with 6 trials of distinct parameters."""
    import optuna

    args = [
        "+sweep=optuna_teacher",
        "+scale=smoke",
        "device=cpu",
        "train_teacher.max_iterations=8",
        f"sweep.smoke_trials={N_TRIALS}",
        "sweep.study_name=shared",
        f"sweep.storage={postgres_url}",
    ]
    script = str(REPO_ROOT / "tests" / "workflows" / "sweep_fake_worker.py")
    procs = [
        subprocess.Popen(
            [sys.executable, script, *args, f"run_dir={tmp_path / f'worker{i}'}"],
            cwd=REPO_ROOT,
            env=plain_python_env(),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        for i in range(N_WORKERS)
    ]
    outputs = [p.communicate(timeout=600)[0] for p in procs]
    assert [p.returncode for p in procs] == [0] * N_WORKERS, "\n".join(o[-3000:] for o in outputs)

    study = optuna.load_study(study_name="shared", storage=postgres_url)
    trials = study.get_trials(deepcopy=False)
    # Each worker stops once finished + running trials reach n_trials; two asking at the same instant may add one.
    assert N_TRIALS <= len(trials) < N_TRIALS + N_WORKERS
    assert all(t.state.is_finished() for t in trials)
    params = [tuple(sorted(t.params.items())) for t in trials]
    assert len(set(params)) == len(params)
    # Every worker ran trials in its own run directory; together they ran each trial once.
    ran = {int(d.name) for i in range(N_WORKERS) for d in (tmp_path / f"worker{i}" / "trials").glob("*")}
    assert ran == {t.number for t in trials}
    assert sum(any((tmp_path / f"worker{i}" / "trials").glob("*")) for i in range(N_WORKERS)) >= 2
    summary = json.loads((tmp_path / "worker0" / "study_summary.json").read_text())
    assert summary["storage"] == postgres_url and summary["best"] is not None
    assert (tmp_path / "worker0" / "best_config.yaml").is_file()
