# SPDX-License-Identifier: Apache-2.0
"""The out-of-library verdict: a best fit that leaves a residual above the floor is ``unexplained``."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from gmloco.deploy.mismatch.attribution import AttributionCfg, Hypothesis, decide
from gmloco.deploy.mismatch.effects import effect
from gmloco.deploy.mismatch.recording import Recording

_S, _P, _C = 4, 5, 3  # segments, samples per segment, channels


def _problem() -> SimpleNamespace:
    """A stand-in Problem: every segment held out, every channel weighted (floor energy = 60 elements)."""
    return SimpleNamespace(held=np.ones(_S, bool), weight=np.ones(_C))


def _hyp(e_held: float) -> Hypothesis:
    """A passing hypothesis that leaves ``e_held`` of held-out residual energy."""
    h = Hypothesis(spec=effect("joint.viscous_damping"), sens=np.zeros((_S, _P, _C, 1)), testable=True)
    h.passed, h.gain_lo_signals, h.e_held = True, 0.5, e_held
    return h


def test_in_library_fit_within_floor_is_explained() -> None:
    """Nominal ratio 4 (r0 = 2 everywhere), fit leaves ratio 1.0 <= 1.5: explained, fraction (240-60)/180 = 1."""
    r0 = np.full((_S, _P, _C), 2.0)
    d = decide(_problem(), r0, [_hyp(60.0)], AttributionCfg())  # type: ignore[arg-type]
    assert d["verdict"] == "explained" and d["winner"] == "joint.viscous_damping" and d["nearest"] is None
    assert np.isclose(d["nominal_energy_ratio"], 4.0) and np.isclose(d["residual_ratio"], 1.0)
    assert np.isclose(d["explained_fraction"], 1.0)


def test_out_of_library_fit_leaving_residual_is_unexplained() -> None:
    """Fit leaves ratio 2.0 > 1.5 though it removes (240-120)/180 = 0.67 >= explain_min: unexplained, nearest named."""
    r0 = np.full((_S, _P, _C), 2.0)
    d = decide(_problem(), r0, [_hyp(120.0)], AttributionCfg())  # type: ignore[arg-type]
    assert d["verdict"] == "unexplained" and d["winner"] is None and d["nearest"] == "joint.viscous_damping"
    assert np.isclose(d["residual_ratio"], 2.0) and np.isclose(d["explained_fraction"], 2.0 / 3.0)
    # The same fit under the previous rule (no residual bound) was called explained.
    old = decide(_problem(), r0, [_hyp(120.0)], AttributionCfg(residual_ratio_max=np.inf))  # type: ignore[arg-type]
    assert old["verdict"] == "explained"


def test_residual_bound_never_touches_recordings_within_the_floor() -> None:
    """Nominal ratio 1.0 < 1.5 (r0 = 1): a weak-regime winner stays explained even with a strict bound."""
    r0 = np.ones((_S, _P, _C))
    d = decide(_problem(), r0, [_hyp(50.0)], AttributionCfg(residual_ratio_max=0.1))  # type: ignore[arg-type]
    assert d["verdict"] == "explained"
    none = decide(_problem(), r0, [], AttributionCfg())  # type: ignore[arg-type]
    assert none["verdict"] == "no_mismatch" and np.isclose(none["residual_ratio"], 1.0)


def test_delay_outside_a_library_without_delay_is_unexplained(delay_rec: Recording) -> None:
    """A hidden 12 ms delay screened against a library without delay or damping is ``unexplained``.

    Coulomb friction, the nearest effect, removes about half the excess energy (enough for ``explain_min``), but
    leaves a held-out residual of about 2.6x the floor. In-library counterpart:
    ``test_attribution.test_planted_delay_is_recovered`` (same recording, delay in the library: ``explained``).
    """
    from gmloco.deploy.mismatch.pipeline import AnalysisCfg, analyze

    lib = ("actuator.gain_scale", "joint.coulomb_friction", "body.mass_error")
    cfg = AnalysisCfg(attribution=AttributionCfg(effects=lib, n_boot=200), mirror_check=False)
    rep = analyze(delay_rec, cfg).report
    assert rep["verdict"] == "unexplained" and rep["winner"] is None
    assert rep["nearest"] in lib
    assert rep["mismatch"]["residual_ratio"] > AttributionCfg().mismatch_ratio
