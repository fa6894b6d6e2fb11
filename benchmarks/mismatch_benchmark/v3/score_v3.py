# SPDX-License-Identifier: Apache-2.0
"""Score the v3 fresh-seed re-run exactly as PROTOCOL.md defines (H1, H2, false positives, parameter error, ...).

Reads ``V3/sand`` and ``V3/plane``: each holds ``rows/``, ``errors/``, ``keys/`` and ``manifest.json``, as the
device sweep left them. It also reads the stored sand nulls (``sand_posthoc/rows``) and plane nulls (``rows/``)
for the pooled false-positive counts. It writes ``V3/summary.json`` and ``V3/scores.md``. The metrics, row
loading and tables are in ``../scoring.py``, shared with ``../v4/score_v4.py``.

    uv run python benchmarks/mismatch_benchmark/v3/score_v3.py --code-commit COMMIT

``--code-commit`` is the commit whose tree the device ran. The script checks three things: that the tool code
there equals the protocol commit's (bookkeeping files aside), and that each manifest's source hash equals the
hash of that tree.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import defaultdict
from pathlib import Path
from typing import Any

from gmloco.deploy.mismatch.benchmark.episodes import episode_list, sand_episode_list

RESULTS_HOME = Path(__file__).resolve().parents[3] / "results/mismatch_benchmark/v3"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
BENCH = HERE.parent
REPO = BENCH.parent.parent
# The shared scoring code lives in benchmarks/mismatch_benchmark/scoring.py, outside any package: put the repository
# root on the import path so that this script also runs standalone (``python benchmarks/.../score_v3.py``).
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))
from benchmarks.mismatch_benchmark import scoring  # noqa: E402

PROTOCOL_COMMIT = "1b8a9cf"
"""The commit that added PROTOCOL.md: the tool code under test."""
CFG = scoring.ScoringCfg(
    label="v3",
    checks=("seed",),
    bookkeeping=("benchmark/sweep.py", "benchmark/episodes.py"),
    null_rows=(
        ("headline_sand_fresh_plus_stored", "sand nulls"),
        ("plane_fresh", "fresh plane nulls"),
        ("all_with_stored", "all nulls with stored"),
    ),
    no_data="not met",
)
"""v3's scoring: rows checked for their seed only; the sweep and the episode seeds are bookkeeping; the
false-positive headline pools the fresh and the stored sand nulls; a target without episodes is not met."""


def nulls(fresh: dict[str, list[dict]]) -> dict[str, Any]:
    """False positives (verdict not ``no_mismatch``; a tool error counts as one) on fresh and stored nulls."""
    fp = scoring.false_positives
    stored_sand = [json.loads(f.read_text()) for f in sorted((BENCH / "sand_posthoc" / "rows").glob("sand-none-*"))]
    stored_plane = [json.loads(f.read_text()) for f in sorted((BENCH / "rows").glob("none-*"))]
    fs, fp_ = fp(fresh.get("sand", [])), fp(fresh.get("plane", []))
    ss, sp = fp(stored_sand), fp(stored_plane)
    cp = scoring.cp
    return {
        "headline_sand_fresh_plus_stored": cp(sum(fs + ss), len(fs + ss)),
        "sand_fresh": cp(sum(fs), len(fs)),
        "plane_fresh": cp(sum(fp_), len(fp_)),
        "fresh_all": cp(sum(fs + fp_), len(fs + fp_)),
        "all_with_stored": cp(sum(fs + fp_ + ss + sp), len(fs + fp_ + ss + sp)),
        "fresh_false_positives": scoring.false_positive_names(fresh),
    }


def main(argv: list[str] | None = None) -> None:
    """Score and write ``summary.json`` and ``scores.md`` into ``--v3``."""
    p = argparse.ArgumentParser()
    p.add_argument("--v3", type=Path, default=HERE, help="folder holding sand/ and plane/ as the device left them")
    p.add_argument("--code-commit", default=None, help="the commit the device ran (provenance check)")
    p.add_argument("--seed-offset", type=int, default=10000)
    p.add_argument("--seeds", type=int, default=2)
    p.add_argument("--sand-nulls", type=int, default=48)
    p.add_argument("--plane-nulls", type=int, default=20)
    a = p.parse_args(argv)
    expected = {
        "sand": sand_episode_list(a.seeds, a.sand_nulls, seed_offset=a.seed_offset),
        "plane": episode_list(a.seeds, a.plane_nulls, seed_offset=a.seed_offset),
    }
    dirs = {s: a.v3 / s for s in expected if (a.v3 / s).exists()}
    fresh: dict[str, list[dict]] = {}
    status: dict[str, list[str]] = defaultdict(list)
    for s, d in dirs.items():
        fresh[s], st = scoring.load_suite(d, expected[s], CFG.checks)
        for k, v in st.items():
            status[k] += v
    for s in expected:
        if s not in dirs:
            status["missing"] += [e["name"] for e in expected[s]]
    summary = {
        "protocol": "results/mismatch_benchmark/v3/PROTOCOL.md",
        "episodes_expected": sum(len(v) for v in expected.values()),
        "episodes_scored": sum(len(v) for v in fresh.values()),
        "complete": not (status["missing"] or status["generation_error"] or status["seed_mismatch"]),
        "status": dict(status),
    } | scoring.sections(fresh, nulls(fresh), dirs, a.code_commit, PROTOCOL_COMMIT, CFG)
    brief = {k: summary[k] for k in ("episodes_expected", "episodes_scored", "complete", "targets")}
    scoring.write(a.v3, summary, CFG, brief)


if __name__ == "__main__":
    main()
