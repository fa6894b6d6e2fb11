# SPDX-License-Identifier: Apache-2.0
"""Benchmark v6's runner matches its pre-registered protocol: one robot per episode, fresh seeds, the pool."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from gmloco.deploy.mismatch.benchmark import v5, v6
from gmloco.deploy.mismatch.benchmark.protocol import TARGETS
from gmloco.deploy.mismatch.effects import EFFECT_IDS

_ROOT = Path(__file__).parents[4] / "results/mismatch_benchmark"
_PROTOCOL = _ROOT / "v6/protocol.md"


def test_episode_count_and_classes_match_the_protocol() -> None:
    """58 episodes: v5's 17 plane classes x 2 seeds, 2 out-of-library classes x 2, 20 nulls; both stages each."""
    line = next(ln for ln in _PROTOCOL.read_text().splitlines() if ln.startswith("Episodes:"))
    want = {s: int(n) for s, n in re.findall(r"(identification) [\d + ]+= (\d+)", line)}
    eps = v6.suite_episodes("identification")
    assert want == {"identification": len(eps)} == {"identification": 58}
    classes = {e["effect"] for e in eps if e["effect"] in EFFECT_IDS}
    assert classes == set(v5.SUITES["plane"]["mid"]) and len(classes) == 17
    assert sum(e["effect"] == "none" for e in eps) == v6.NULLS_PER_SUITE == 20
    assert all(e["stages"] == [{"support": "gantry", "chirp": True}, {}] for e in eps)


def test_seeds_are_fresh_and_apart_from_v5_and_the_pilot() -> None:
    """No seed of v6 is one of v5's, an earlier one (< 30000) or the pilot's development seed 61001."""
    seeds = [e["seed"] for e in v6.suite_episodes("identification")]
    v5_seeds = {e["seed"] for s in v5.SUITES for e in v5.suite_episodes(s)}
    assert len(seeds) == len(set(seeds)) and min(seeds) >= 30000
    assert not set(seeds) & (v5_seeds | {61001})
    assert "54000 + 10 i + s" in _PROTOCOL.read_text() and v6.SEED_BASE == {"identification": 54000}


def test_targets_and_pool_match_the_protocol() -> None:
    """Targets are issue 41's numbers; the pool carries v5's sand suite over."""
    text = _PROTOCOL.read_text()
    assert "Pooled top-1 >= 0.8" in text and TARGETS["top1_pooled"] == 0.8
    assert "False positives <= 5 %" in text and TARGETS["false_positive_max"] == 0.05
    assert "`unexplained` >= 80 %" in text and TARGETS["ool_unexplained"] == 0.8
    assert v6.V6.carried == {"sand": "v5/sand"} and "results/mismatch_benchmark/v5/sand/rows" in text


def test_score_only_pools_the_suite_with_the_carried_sand_rows(tmp_path: Path) -> None:
    """Scoring a v6 folder beside a v5 one pools both; the summary names the carried folder."""
    row = {"name": "identification-none-0", "effect": "none", "strength": "none", "verdict": "no_mismatch"}
    (tmp_path / "v6/identification/rows").mkdir(parents=True)
    (tmp_path / "v6/identification/rows/identification-none-0.json").write_text(json.dumps(row))
    (tmp_path / "v5/sand/rows").mkdir(parents=True)
    sand = {**row, "name": "sand-none-0", "verdict": "explained"}
    (tmp_path / "v5/sand/rows/sand-none-0.json").write_text(json.dumps(sand))
    assert v6.main(["--out", str(tmp_path / "v6"), "--suite", "identification", "--score-only"]) == 0
    pool = json.loads((tmp_path / "v6/summary_pooled.json").read_text())
    assert pool["pooled"]["null_episodes"] == 2 and pool["pooled"]["false_positive_rate"] == 0.5
    assert pool["carried"] == {"sand": str(tmp_path / "v5/sand")}


@pytest.mark.parametrize(("extra", "message"), [(["--suite", "sand"], "invalid choice: 'sand'"),
                                               (["--suite", "identification", "--workers", "0"], "must be >= 1")])  # fmt: skip
def test_bad_input_exits_2(extra: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A suite of another version or a bad flag runs nothing and exits with 2."""
    with pytest.raises(SystemExit) as stop:
        v6.main(["--out", str(tmp_path), *extra])
    assert stop.value.code == 2
    assert message in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
