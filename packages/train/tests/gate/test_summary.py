# SPDX-License-Identifier: Apache-2.0
"""The gate's reduction of episode rows to the issue's keys and the pass map, on hand-made rows."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from gmloco.train.gate.config import GateCfg, GateThresholdsCfg
from gmloco.train.gate.rollout import GateCell
from gmloco.train.gate.summary import gate_metrics, gate_pass


def _cfg() -> GateCfg:
    """Two materials, two speeds, one yaw rate, 2 episodes per cell."""
    return GateCfg(materials=("basalt", "poppy_seed"), speeds=(0.5, 1.0), yaw_rates=(0.5,), repeats=2, apex_speed=1.0)


def _row(kind: str, material: str, command: tuple[float, float, float], **values: Any) -> dict[str, Any]:
    """An episode row with defaults of a perfect episode."""
    cell = GateCell(kind, material, 1500.0, 0.5, 0.5, command)  # type: ignore[arg-type]
    row = {"cell": cell, "failed": False, "vel_error": 0.05, "yaw_rate": command[2], "drift_deg": 1.0, "apex_m": []}
    return row | values


def _rows(apex_soft: float, failed_soft: bool = False) -> list[dict[str, Any]]:
    """Rows of a policy whose swing apex is 0.09 m on basalt and ``apex_soft`` on poppy seed."""
    rows = []
    for m, apex in (("basalt", 0.09), ("poppy_seed", apex_soft)):
        for v in (0.5, 1.0):
            rows += [_row("forward", m, (v, 0.0, 0.0), apex_m=[apex, apex]) for _ in range(2)]
        rows += [_row("yaw", m, (0.5, 0.0, 0.5), yaw_rate=0.47) for _ in range(2)]
        rows += [_row("circle", m, (1.0, 0.0, 0.5), dtw_m=0.04) for _ in range(2)]
    if failed_soft:
        rows[2]["failed"] = True  # rows 0-1: basalt at 0.5 m/s, rows 2-3: basalt at 1.0 m/s
    eta_true = np.linspace(0.1, 0.5, 50)
    rows += [_row("held_out", "held_out_rho2100_mu0.700", (1.0, 0.0, 0.0), eta=(eta_true + 0.01, eta_true))]
    return rows


def test_metrics_of_a_passing_policy() -> None:
    """Means per cell: success 100 %, ratio 0.94, apex 9 -> 16 cm, R^2 of a 1 cm offset on a 0.1-0.5 ramp."""
    m = gate_metrics(_cfg(), _rows(0.16))
    assert m["success_pct"] == {"basalt": {"0.5": 100.0, "1": 100.0}, "poppy_seed": {"0.5": 100.0, "1": 100.0}}
    np.testing.assert_allclose(m["yaw_rate_ratio"]["basalt"]["0.5"], 0.94)
    np.testing.assert_allclose([m["swing_apex_cm"]["basalt"], m["swing_apex_cm"]["poppy_seed"]], [9.0, 16.0])
    # R^2 = 1 - n 0.01^2 / sum (y - mean)^2, y = linspace(0.1, 0.5, 50): var = 0.4^2 (n+1) / (12 (n-1)).
    var = 0.4**2 * 51 / (12 * 49)
    np.testing.assert_allclose(m["eta_r2_heldout"], 1.0 - 0.01**2 / var, rtol=1e-9)
    by_material = m["eta_heldout_by_material"]["held_out_rho2100_mu0.700"]
    np.testing.assert_allclose([by_material["true"], by_material["decoded_mean"]], [0.3, 0.31], rtol=1e-9)
    np.testing.assert_allclose(by_material["decoded_std"], np.linspace(0.1, 0.5, 50).std(), rtol=1e-9)
    m["gpu_minutes"] = 120.0
    verdict = gate_pass(m, GateThresholdsCfg(), ("basalt", "poppy_seed"))
    assert verdict == dict.fromkeys(verdict, True)


@pytest.mark.parametrize(
    ("change", "failing"),
    [
        ({"apex_soft": 0.12}, "swing_apex_cm"),
        ({"failed_soft": True}, "success_pct"),
        ({"gpu": 200.0}, "gpu_minutes"),
        ({"gpu": None}, "gpu_minutes"),
    ],
)
def test_pass_map_names_the_failing_key(change: dict[str, Any], failing: str) -> None:
    """A 3 cm apex rise, one fall, 200 GPU minutes or none recorded fail their key and ``all`` only."""
    m = gate_metrics(_cfg(), _rows(change.get("apex_soft", 0.16), change.get("failed_soft", False)))
    m["gpu_minutes"] = change.get("gpu", 120.0)
    verdict = gate_pass(m, GateThresholdsCfg(), ("basalt", "poppy_seed"))
    assert {k for k, ok in verdict.items() if not ok} == {failing, "all"}


def test_no_decoded_eta_fails_eta_key() -> None:
    """A PPO baseline has no decoded eta: ``eta_r2_heldout`` is None and fails."""
    rows = [r for r in _rows(0.16) if r["cell"].kind != "held_out"]
    m = gate_metrics(_cfg(), rows) | {"gpu_minutes": 10.0}
    assert m["eta_r2_heldout"] is None
    assert not gate_pass(m, GateThresholdsCfg(), ("basalt", "poppy_seed"))["eta_r2_heldout"]
    assert math.isclose(m["circle_dtw_m"]["basalt"], 0.04)


def test_failures_and_stance_sinkage_say_why_episodes_ended() -> None:
    """Each failed forward episode is listed with its term and time; stance depths average per cell, in cm."""
    rows = _rows(0.16)
    rows[2] |= {"failed": True, "failure": "base_too_low", "fail_s": 3.5}
    for r in rows[:4]:
        r["stance_sink_m"], r["stance_sink_peak_m"] = 0.04, 0.07
    m = gate_metrics(_cfg(), rows)
    assert m["failures"]["basalt"] == {"0.5": [], "1": ["base_too_low at 3.50 s"]}
    assert m["failures"]["poppy_seed"] == {"0.5": [], "1": []}
    np.testing.assert_allclose(m["stance_sink_cm"]["basalt"]["1"], 4.0)
    assert m["stance_sink_cm"]["poppy_seed"]["1"] is None  # rows without the read-out
    np.testing.assert_allclose(m["stance_sink_peak_cm"]["basalt"]["1"], 7.0)
    assert m["stance_sink_peak_cm"]["poppy_seed"]["1"] is None


def test_failure_is_the_first_term_that_fired() -> None:
    """Of two terms the earlier one ends the episode; an episode no term ended survived."""
    from gmloco.train.gate.rollout import _failure

    steps, dt = 10, 0.02
    tilt, low = np.zeros((steps, 2)), np.zeros((steps, 2))
    tilt[6, 0], low[4, 0] = 1.0, 1.0
    raw = {"ended_tilt": tilt, "ended_base_too_low": low}
    name, when = _failure(raw, 0, dt)
    assert name == "base_too_low" and math.isclose(when, 5 * dt)
    name, when = _failure(raw, 1, dt)
    assert name is None and math.isnan(when)


def test_episode_rows_read_the_peak_stance_depth_of_alive_contact_steps() -> None:
    """The peak is the 95th percentile of the depth of feet in contact while alive; swing feet do not count."""
    from gmloco.train.gate.rollout import GateCell, episode_rows

    steps = 100
    height = np.zeros((steps, 1, 2))
    height[:, 0, 0] = -np.linspace(0.0, 0.05, steps)  # foot 0 in contact, sinking 0-5 cm
    height[:, 0, 1] = -0.5  # foot 1 deep but never in contact
    contact = np.zeros((steps, 1, 2))
    contact[:, 0, 0] = 1.0
    raw = {
        "alive": np.ones((steps, 1)),
        "contact": contact,
        "height": height,
        **{k: np.zeros((steps, 1)) for k in ("vx", "vy", "wz", "yaw", "x", "y", "eta_true")},
        **{k: np.zeros(1) for k in ("x0", "y0", "yaw0")},
    }
    cell = GateCell("forward", "basalt", 2000.0, 0.4, 0.4, (0.5, 0.0, 0.0))
    (row,) = episode_rows(_cfg(), [cell], raw, 0.02)
    np.testing.assert_allclose(row["stance_sink_m"], 0.025)
    np.testing.assert_allclose(row["stance_sink_peak_m"], np.percentile(np.linspace(0.0, 0.05, steps), 95.0))


def test_success_by_the_course_rule() -> None:
    """A survivor short of its course fails MPM's rule only; rows without ``course_s`` give no course table."""
    rows = _rows(0.16)
    for r in rows:
        if r["cell"].kind == "forward":
            r["course_s"] = 8.0
    rows[2]["course_s"] = None  # basalt 1.0 m/s: survived, short of its course
    rows[3] |= {"failed": True, "failure": "tilt", "fail_s": 3.0}  # basalt 1.0 m/s: fell (course_s ignored)
    m = gate_metrics(_cfg(), rows)
    assert m["success_pct"]["basalt"] == {"0.5": 100.0, "1": 50.0}
    assert m["success_course_pct"]["basalt"] == {"0.5": 100.0, "1": 0.0}
    assert m["success_course_pct"]["poppy_seed"] == {"0.5": 100.0, "1": 100.0}
    assert m["failures"]["basalt"]["1"] == ["tilt at 3.00 s", "course_unfinished"]
    assert gate_metrics(_cfg(), _rows(0.16))["success_course_pct"]["basalt"] == {"0.5": None, "1": None}


@pytest.mark.parametrize(("kind", "failing"), [("yaw", "yaw_rate_ratio"), ("circle", "circle_dtw_m")])
def test_a_fall_while_turning_fails_its_key(kind: str, failing: str) -> None:
    """A robot that falls in a yaw or circle cell fails that key even when its alive steps tracked the command."""
    rows = _rows(0.16)
    turn = next(i for i, r in enumerate(rows) if r["cell"].kind == kind and r["cell"].material == "poppy_seed")
    rows[turn]["failed"] = True
    m = gate_metrics(_cfg(), rows) | {"gpu_minutes": 10.0}
    falls = m["turn_falls"][kind]["poppy_seed"]
    assert (falls["0.5"] if kind == "yaw" else falls) == 1
    verdict = gate_pass(m, GateThresholdsCfg(), ("basalt", "poppy_seed"))
    assert {k for k, ok in verdict.items() if not ok} == {failing, "all"}
