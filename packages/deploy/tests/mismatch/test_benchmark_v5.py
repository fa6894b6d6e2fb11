# SPDX-License-Identifier: Apache-2.0
"""Benchmark v5's runner matches its pre-registered protocol: counts, fresh seeds, targets, bad input."""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import pytest

from gmloco.deploy.mismatch.benchmark.protocol_cfg import ProtocolRunCfg
from gmloco.deploy.mismatch.benchmark.v5 import (
    FLAGS,
    NULLS_PER_SUITE,
    SEED_BASE,
    SUITES,
    TARGETS,
    _parse,
    main,
    suite_episodes,
)
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


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--part", "3/2"], "0 <= i < n"),
        (["--part", "half"], "give I/N with whole numbers"),
        (["--workers", "0"], "--workers 0 must be >= 1"),
        (["--deadline-s", "0"], "--deadline-s 0.0 must be > 0"),
        (["--suite", "gravel"], "invalid choice: 'gravel'"),
    ],
)
def test_bad_input_exits_2(extra: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A malformed or out-of-range flag runs nothing and exits with 2, saying what it takes."""
    with pytest.raises(SystemExit) as stop:
        main(["--out", str(tmp_path), "--suite", "fixed", *extra])
    assert stop.value.code == 2
    assert message in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def _recorded_commands() -> list[list[str]]:
    """Every v5 command written down: the protocol's and README's lines and the argv of every run file."""
    root = _PROTOCOL.parent
    lines = [ln for f in (_PROTOCOL, root / "README.md") for ln in f.read_text().splitlines()]
    argvs = [ln.split("benchmark.v5", 1)[1].split() for ln in lines if "-m gmloco.deploy.mismatch.benchmark.v5 " in ln]
    argvs += [json.loads(f.read_text())["argv"] for f in sorted(root.glob("*/runs/*.json"))]
    return argvs


def test_recorded_commands_parse() -> None:
    """The flag table reads every recorded command as the hand-written parser did (suite, workers, resume)."""
    argvs = _recorded_commands()
    assert len(argvs) >= 6
    for argv in argvs:
        root, cfg = _parse(argv)
        assert str(root) == argv[argv.index("--out") + 1] and cfg.suite == argv[argv.index("--suite") + 1]
        assert cfg.resume == ("--resume" in argv)
        if "--workers" in argv:
            assert cfg.workers == int(argv[argv.index("--workers") + 1])
        if "--deadline-s" in argv:
            assert cfg.deadline_s == float(argv[argv.index("--deadline-s") + 1])


def test_flags_come_from_the_config() -> None:
    """Every generated flag sets a field of ProtocolRunCfg and the defaults are the config's."""
    fields = {f.name for f in dataclasses.fields(ProtocolRunCfg)}
    assert {flag.path for flag in FLAGS} == fields - {"suite"}
    _, cfg = _parse(["--out", "x", "--suite", "sand"])
    assert cfg == ProtocolRunCfg(suite="sand")
    _, cfg = _parse(["--out", "x", "--suite", "plane", "--only", "plane-none,plane-ool", "--list", "--score-only"])
    assert (cfg.only, cfg.list_episodes, cfg.score_only) == (("plane-none", "plane-ool"), True, True)
