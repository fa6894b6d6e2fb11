# SPDX-License-Identifier: Apache-2.0
"""The paper's two layouts of the MPM tables: the contact-model ablation and the per-terrain table."""

from __future__ import annotations

import math
from typing import Any

import pytest

from gmloco.eval.report.tables_mpm import (
    ABLATION_COLUMNS,
    paper_metrics,
    table_ablation,
    table_per_terrain,
    table_terrains,
)


def _episodes(terrain: str, scenario: str, wins: int, n: int, path: float = 0.3, vel: float = 0.2) -> list[dict]:
    return [{"terrain": terrain, "scenario": scenario, "speed": 1.0, "success": k < wins, "alive_s": 10.0,
             "vel_error": vel, "heading_error_deg": 2.0, "yaw_error": 0.1, "path_error": path,
             "mean_sinkage": 0.05}
            for k in range(n)]  # fmt: skip


def _rows() -> list[list[Any]]:
    """td: dry sand straight 8/10 and circle 5/10 (DTW 0.4 m), basalt straight 9/10; rigid: dry sand straight 0/10."""
    td = _episodes("dry_sand", "straight", 8, 10) + _episodes("dry_sand", "circle", 5, 10, path=0.4)
    td += _episodes("basalt", "straight", 9, 10, vel=0.1)
    return table_terrains(td, "td") + table_terrains(_episodes("dry_sand", "straight", 0, 10, vel=0.9), "rigid")


def test_ablation_puts_straight_and_circle_side_by_side() -> None:
    """One row per (terrain, policy), terrains grouped; a scenario not walked is 0 episodes and NaN."""
    rows = table_ablation(_rows())
    assert [r[:2] for r in rows] == [["dry_sand", "td"], ["dry_sand", "rigid"], ["basalt", "td"]]
    td = dict(zip(ABLATION_COLUMNS, rows[0], strict=True))
    assert (td["straight_episodes"], td["straight_success_pct"]) == (10, pytest.approx(80.0))
    assert (td["circle_episodes"], td["circle_success_pct"]) == (10, pytest.approx(50.0))
    assert td["circle_path_error_m"] == pytest.approx(0.4)
    rigid = dict(zip(ABLATION_COLUMNS, rows[1], strict=True))
    assert rigid["circle_episodes"] == 0 and math.isnan(rigid["circle_success_pct"])


def test_per_terrain_gives_each_policy_its_columns() -> None:
    """Rows are terrains (straight walks), columns each policy's success and tracking errors; NaN where not run."""
    header, body = table_per_terrain(_rows())
    assert header[:5] == ["terrain", "td: success %", "td: vel error [m/s]", "td: heading error [deg]",
                          "td: yaw-rate error [rad/s]"]  # fmt: skip
    assert header[5] == "rigid: success %"
    by = {r[0]: dict(zip(header, r, strict=True)) for r in body}
    assert set(by) == {"dry_sand", "basalt"}
    assert by["dry_sand"]["td: success %"] == pytest.approx(80.0)
    assert by["dry_sand"]["rigid: vel error [m/s]"] == pytest.approx(0.9)
    assert by["basalt"]["td: vel error [m/s]"] == pytest.approx(0.1)
    assert math.isnan(by["basalt"]["rigid: success %"])


def test_paper_metrics_keys_per_policy_terrain_scenario() -> None:
    """Summary keys of the paper per (policy, terrain, scenario): td dry sand circle 5/10, DTW 0.4 m, 2 degrees."""
    got = paper_metrics(_rows())
    assert set(got) == {"td", "rigid"} and set(got["td"]) == {"dry_sand", "basalt"}
    assert got["td"]["dry_sand"]["circle"] == {"success_pct": pytest.approx(50.0), "vel_error_mps": pytest.approx(0.2),
                                              "heading_error_deg": pytest.approx(2.0),
                                              "path_error_m": pytest.approx(0.4), "episodes": 10}  # fmt: skip
    assert got["rigid"]["dry_sand"]["straight"]["success_pct"] == 0.0
    older = [{k: v for k, v in e.items() if k != "heading_error_deg"} for e in _episodes("basalt", "straight", 1, 2)]
    assert paper_metrics(table_terrains(older, "old"))["old"]["basalt"]["straight"]["heading_error_deg"] is None
