# SPDX-License-Identifier: Apache-2.0
"""Benchmark v5's runner matches its pre-registered protocol: counts, fresh seeds, targets, bad input."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from gmloco.deploy.mismatch.benchmark.v5 import NULLS_PER_SUITE, SEED_BASE, SUITES, TARGETS, main, suite_episodes
from gmloco.deploy.mismatch.effects import EFFECT_IDS, effect

_PROTOCOL = Path(__file__).parents[4] / "results/mismatch_benchmark/v5/protocol.md"


def test_episode_counts_match_the_protocol() -> None:
    """Each suite's episode count is the one written in protocol.md (plane 58, sand 62, fixed 54)."""
    text = _PROTOCOL.read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith("Episodes:"))
    want = {s: int(n) for s, n in re.findall(r"(plane|sand|fixed) [\d + ]+= (\d+)", line)}
    assert want == {s: len(suite_episodes(s)) for s in SUITES}


def test_seeds_are_fresh_unique_and_classes_in_library() -> None:
    """Seeds are unique across suites and >= 30000; every in-library class names a library effect."""
    seeds = [e["seed"] for s in SUITES for e in suite_episodes(s)]
    assert len(seeds) == len(set(seeds)) and min(seeds) >= 30000
    assert min(SEED_BASE.values()) >= 30000
    for s in SUITES:
        eps = suite_episodes(s)
        assert sum(e["effect"] == "none" for e in eps) == NULLS_PER_SUITE >= 20
        for e in eps:
            if e["effect"] in EFFECT_IDS:
                spec = effect(e["effect"])
                assert sum(len(v) for v in e["params"].values()) == spec.size, e["name"]
    assert not any(e["effect"].startswith("terrain.") for e in suite_episodes("fixed"))
    assert all(e["support"] == "gantry" and e["chirp"] for e in suite_episodes("fixed"))


def test_targets_match_the_protocol() -> None:
    """The runner's targets are the protocol's numbers."""
    text = _PROTOCOL.read_text()
    assert "Pooled top-1 >= 0.8" in text and TARGETS["top1_pooled"] == 0.8
    assert "False positives <= 5 %" in text and TARGETS["false_positive_max"] == 0.05
    assert "`unexplained` >= 80 %" in text and TARGETS["ool_unexplained"] == 0.8


def test_bad_part_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A malformed --part runs nothing and exits with 2, saying what it takes."""
    assert main(["--out", str(tmp_path), "--suite", "fixed", "--part", "3/2"]) == 2
    assert "0 <= i < n" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
