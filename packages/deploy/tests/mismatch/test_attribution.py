# SPDX-License-Identifier: Apache-2.0
"""End-to-end attribution on tiny recordings (a 3-effect screen keeps them fast)."""

from __future__ import annotations

import numpy as np

from gmloco.deploy.mismatch.attribution import AttributionCfg
from gmloco.deploy.mismatch.pipeline import AnalysisCfg, analyze

_SMALL = ("actuator.delay", "actuator.gain_scale", "joint.viscous_damping")


def _cfg() -> AnalysisCfg:
    """Small screen, no mirror check (tested separately)."""
    return AnalysisCfg(attribution=AttributionCfg(effects=_SMALL, n_boot=200), mirror_check=False)


def test_planted_delay_is_recovered(delay_rec: object) -> None:
    """A hidden 12 ms delay is named, fitted within 25%, and improves the held-out fit."""
    rep = analyze(delay_rec, _cfg()).report
    assert rep["verdict"] == "explained" and rep["winner"] == "actuator.delay"
    h = next(h for h in rep["hypotheses"] if h["id"] == "actuator.delay")
    assert abs(h["params"]["delay"]["value"] - 0.012) < 0.25 * 0.012
    ba = rep["before_after"]["heldout"]
    assert ba["nrmse_fitted"]["q"] < ba["nrmse_nominal"]["q"]


def test_null_recording_is_no_mismatch(null_rec: object) -> None:
    """With nuisances and noise but no hidden effect, nothing passes the detection rule."""
    rep = analyze(null_rec, _cfg()).report
    assert rep["verdict"] == "no_mismatch", [
        (h["id"], h.get("dbic"), h.get("heldout_gain")) for h in rep["hypotheses"][:3]
    ]
    assert rep["winner"] is None


def test_standing_leaves_swing_effects_untested(null_rec: object) -> None:
    """Torque-speed saturation cannot be tested without torques near the limit: it is listed with a remedy."""
    cfg = AnalysisCfg(
        attribution=AttributionCfg(effects=("actuator.torque_speed", "actuator.delay"), n_boot=100), mirror_check=False
    )
    rep = analyze(null_rec, cfg).report
    untested = {u["id"]: u for u in rep["untested"]}
    assert "actuator.torque_speed" in untested
    assert "limit" in untested["actuator.torque_speed"]["needs"]
    assert np.isfinite(rep["recording"]["n_eff"])
