# SPDX-License-Identifier: Apache-2.0
"""Score benchmark v4 exactly as PROTOCOL.md defines (H1, H2, false positives, parameter error, ...).

``../v3/score_v3.py``'s scoring adapted to v4 (the code both share is in ``../scoring.py``): the episode lists
are the composite-motion sand suite with the ``v4`` strength table and 64 nulls, and the plane suite with 20
nulls, both at seed offset 20 000. The false-positive headline is over the fresh composite sand nulls alone (no
stored nulls). Every row must carry its episode's seed, parameters and motion.

Reads ``V4/sand`` and ``V4/plane``: each holds ``rows/``, ``errors/``, ``keys/`` and ``manifest.json``, as the
device sweep left them. A folder that is absent, empty or partial is scored on what it holds, and every episode
without a row is listed as missing (``scores.md`` and ``summary.json`` → ``status``). It writes
``V4/summary.json`` and ``V4/scores.md``.

    uv run python benchmarks/mismatch_benchmark/v4/score_v4.py --code-commit COMMIT

``--code-commit`` is the commit whose tree the device ran. The script checks that the tool code there equals
the protocol commit's (the sweep's bookkeeping aside), that each manifest's source hash equals the hash of that
tree, and that each invocation used the ``v4`` strength table.
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path
from typing import Any

from gmloco.deploy.mismatch.benchmark.episodes import episode_list, sand_episode_list

RESULTS_HOME = Path(__file__).resolve().parents[3] / "results/mismatch_benchmark/v4"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
REPO = HERE.parents[2]
# ../scoring.py lies outside any package: the repository root goes on the import path (see score_v3.py).
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))
from benchmarks.mismatch_benchmark import scoring  # noqa: E402

PROTOCOL = "results/mismatch_benchmark/v4/PROTOCOL.md"
SEED_OFFSET, SEEDS, SAND_NULLS, PLANE_NULLS, TABLE, MOTION = 20000, 2, 64, 20, "v4", "composite"
"""The protocol's episode lists: ``sweep --seeds 2 --seed-offset 20000 --strength-table v4``, sand with
``--motion composite --nulls 64``, plane with ``--nulls 20``."""
CFG = scoring.ScoringCfg(
    label="v4",
    checks=("seed", "params", "motion"),
    bookkeeping=("benchmark/sweep.py",),
    null_rows=(
        ("headline_sand_composite_fresh", "fresh composite sand nulls"),
        ("plane_fresh", "fresh plane nulls"),
        ("fresh_all", "all fresh nulls"),
    ),
    no_data="no episodes",
    strength_table=TABLE,
    report_partial=True,
)
"""v4's scoring: every row's seed, parameters and motion are checked; only the sweep is bookkeeping (the
strength tables in ``benchmark/episodes.py`` are not); every invocation must have used the ``v4`` table; the
false-positive headline is the fresh composite sand nulls; partial sets are reported per suite."""


def protocol_commit() -> str | None:
    """The commit that added ``PROTOCOL.md`` (the tool code under test), None before it is committed."""
    return scoring.commit_adding(PROTOCOL)


def expected_lists() -> dict[str, list[dict]]:
    """The protocol's episodes per suite: 96 composite sand episodes and 48 plane episodes."""
    return {
        "sand": sand_episode_list(SEEDS, SAND_NULLS, seed_offset=SEED_OFFSET, motion=MOTION, table=TABLE),
        "plane": episode_list(SEEDS, PLANE_NULLS, seed_offset=SEED_OFFSET, table=TABLE),
    }


def nulls(fresh: dict[str, list[dict]]) -> dict[str, Any]:
    """False positives (verdict not ``no_mismatch``; a tool error counts as one) on the fresh nulls.

    The headline is the fresh composite sand nulls alone (the protocol's decision 2): no stored null enters.
    """
    fs, fp_ = scoring.false_positives(fresh.get("sand", [])), scoring.false_positives(fresh.get("plane", []))
    return {
        "headline_sand_composite_fresh": scoring.cp(sum(fs), len(fs)),
        "plane_fresh": scoring.cp(sum(fp_), len(fp_)),
        "fresh_all": scoring.cp(sum(fs + fp_), len(fs + fp_)),
        "fresh_false_positives": scoring.false_positive_names(fresh),
    }


def main(argv: list[str] | None = None) -> None:
    """Score and write ``summary.json`` and ``scores.md`` into ``--v4``."""
    p = argparse.ArgumentParser()
    p.add_argument("--v4", type=Path, default=HERE, help="folder holding sand/ and plane/ as the device left them")
    p.add_argument("--code-commit", default=None, help="the commit the device ran (provenance check)")
    a = p.parse_args(argv)
    expected = expected_lists()
    dirs = {s: a.v4 / s for s in expected if (a.v4 / s).exists()}
    fresh: dict[str, list[dict]] = {s: [] for s in expected}
    status: dict[str, list[str]] = defaultdict(list)
    for k in ("missing", "generation_error", "tool_error", "seed_mismatch", "params_mismatch", "motion_mismatch"):
        status[k] = []
    status["superseded_error"] = []
    missing_per_suite: dict[str, list[str]] = {}
    for s in expected:
        if s in dirs:
            fresh[s], st = scoring.load_suite(dirs[s], expected[s], CFG.checks)
        else:
            st = {"missing": [e["name"] for e in expected[s]]}
        missing_per_suite[s] = st["missing"]
        for k, v in st.items():
            status[k] += v
    bad = ("missing", "generation_error", "seed_mismatch", "params_mismatch", "motion_mismatch")
    summary = {
        "protocol": PROTOCOL,
        "episodes_expected": sum(len(v) for v in expected.values()),
        "episodes_expected_per_suite": {s: len(v) for s, v in expected.items()},
        "episodes_scored": sum(len(v) for v in fresh.values()),
        "complete": not any(status[k] for k in bad),
        "missing_per_suite": missing_per_suite,
        "status": dict(status),
    } | scoring.sections(fresh, nulls(fresh), dirs, a.code_commit, protocol_commit(), CFG)
    brief = {k: summary[k] for k in ("episodes_expected", "episodes_scored", "complete", "targets")}
    scoring.write(a.v4, summary, CFG, brief | {"missing": {k: len(v) for k, v in missing_per_suite.items()}})


if __name__ == "__main__":
    main()
