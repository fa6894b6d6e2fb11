# SPDX-License-Identifier: Apache-2.0
"""End-to-end attribution on tiny recordings (a 3-effect screen keeps them fast)."""

from __future__ import annotations

from functools import partial

import numpy as np

from gmloco.deploy.mismatch.attribution import AttributionCfg
from gmloco.deploy.mismatch.pipeline import AnalysisCfg, analyze
from gmloco.deploy.mismatch.recording import Recording

_SMALL = ("actuator.delay", "actuator.gain_scale", "joint.viscous_damping")


def _cfg() -> AnalysisCfg:
    """Small screen, no mirror check (tested separately)."""
    return AnalysisCfg(attribution=AttributionCfg(effects=_SMALL, n_boot=200), mirror_check=False)


def test_planted_delay_is_recovered(delay_rec: Recording) -> None:
    """A hidden 12 ms delay is named, fitted within 25%, and improves the held-out fit."""
    rep = analyze(delay_rec, _cfg()).report
    assert rep["verdict"] == "explained" and rep["winner"] == "actuator.delay"
    h = next(h for h in rep["hypotheses"] if h["id"] == "actuator.delay")
    assert abs(h["params"]["delay"]["value"] - 0.012) < 0.25 * 0.012
    ba = rep["before_after"]["heldout"]
    assert ba["nrmse_fitted"]["q"] < ba["nrmse_nominal"]["q"]


def test_null_recording_is_no_mismatch(null_rec: Recording) -> None:
    """With nuisances and noise but no hidden effect, nothing passes the detection rule."""
    rep = analyze(null_rec, _cfg()).report
    assert rep["verdict"] == "no_mismatch", [
        (h["id"], h.get("dbic"), h.get("heldout_gain")) for h in rep["hypotheses"][:3]
    ]
    assert rep["winner"] is None


def test_standing_leaves_swing_effects_untested(null_rec: Recording) -> None:
    """Torque-speed saturation cannot be tested without torques near the limit: it is listed with a remedy."""
    cfg = AnalysisCfg(
        attribution=AttributionCfg(effects=("actuator.torque_speed", "actuator.delay"), n_boot=100), mirror_check=False
    )
    rep = analyze(null_rec, cfg).report
    untested = {u["id"]: u for u in rep["untested"]}
    assert "actuator.torque_speed" in untested
    assert "limit" in untested["actuator.torque_speed"]["needs"]
    assert np.isfinite(rep["recording"]["n_eff"])


def test_param_cov_sandwich_widens_for_block_correlated_misfit() -> None:
    """Residuals that share a sign within each time block (a misfit) widen the interval beyond Gauss-Newton."""
    from gmloco.deploy.mismatch.attribution import _param_cov

    rng = np.random.default_rng(0)
    blocks = np.repeat(np.arange(8), 10)  # 8 blocks of 10 segments, 5 residuals each
    J = rng.normal(size=(80 * 5, 1)) + 1.0
    white = rng.normal(size=80 * 5)
    # white residual: the sandwich agrees with Gauss-Newton (s2 (J^T J)^-1) up to sampling error, so the larger is
    # within a factor ~2 of it, and the quantile is Student's t with G - 1 = 7 dof (2.365)
    cov_w, q = _param_cov(J, white, blocks, float(white @ white) / 399)
    gn = float(white @ white) / 399 / float(J[:, 0] @ J[:, 0])
    np.testing.assert_allclose(q, 2.3646, atol=1e-3)
    assert gn <= cov_w[0, 0] <= 4.0 * gn
    # block-constant residual (+-1 per block, same direction as J): the cluster sum carries it in full
    shared = np.repeat(rng.choice([-1.0, 1.0], 8), 50) * J[:, 0]
    cov_s, _ = _param_cov(J, shared, blocks, float(shared @ shared) / 399)
    gn_s = float(shared @ shared) / 399 / float(J[:, 0] @ J[:, 0])
    assert cov_s[0, 0] > 10.0 * gn_s


class _RoughBowl:
    """A stand-in training problem: a quadratic bowl around ``truth`` plus a fine ripple in every component.

    The ripple (period 4 mm, below the scale of the fit's steps) makes the finite-difference Jacobian of a point
    mislead Gauss-Newton, as the stiff sand contact does for encoder offsets in a closed-loop replay.
    """

    def __init__(self, spec_id: str, truth: np.ndarray, amp: float = 1.0, period: float = 0.004) -> None:
        self.spec_id, self.truth, self.amp, self.period = spec_id, truth, amp, period
        self.train = np.ones(4, bool)
        self.calls = 0
        self.y, self.sigma, self.weight = np.zeros((4, 6)), 1.0, 1.0

    def simulate(self, params: dict[str, np.ndarray], mask: np.ndarray | None = None) -> np.ndarray:
        """The replay whose residual against the zero recording is :meth:`resid` (y - sim) / sigma * weight."""
        return -self.resid(params, mask).reshape(self.y.shape)

    def normalise(self, y_sim: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
        """Normalised residual of a replay, as :meth:`gmloco.deploy.mismatch.problem.Problem.normalise`."""
        return (self.y - y_sim) / self.sigma * self.weight

    def resid(self, params: dict[str, np.ndarray], mask: np.ndarray | None = None) -> np.ndarray:
        self.calls += 1
        th = params[self.spec_id]
        return np.concatenate([(th - self.truth) / 0.006, self.amp * np.sin(2 * np.pi * th / self.period)])


def _rough_fit(pattern_sweeps: int, truth: np.ndarray) -> tuple[np.ndarray, float]:
    from typing import cast

    from gmloco.deploy.mismatch.attribution import Hypothesis, _lm
    from gmloco.deploy.mismatch.effects import effect
    from gmloco.deploy.mismatch.problem import Problem

    spec = effect("sensor.encoder_offset")
    pb = _RoughBowl(spec.id, truth)
    hyp = Hypothesis(spec, np.zeros(1), True, theta_lin=np.zeros(spec.size))
    theta, r, J = _lm(cast(Problem, pb), hyp, AttributionCfg(pattern_sweeps=pattern_sweeps))
    assert J.shape == (r.size, spec.size)
    return theta, float(r @ r)


def test_vector_fit_escapes_a_rough_valley_with_the_pattern_search() -> None:
    """Levenberg-Marquardt alone stalls on a rough bowl; the coordinate pattern search reaches the minimum."""
    truth = np.zeros(12)
    truth[3], truth[4], truth[6] = 0.03, 0.02, -0.03  # the benchmark's offsets [rad]
    th_lm, e_lm = _rough_fit(0, truth)
    th, e = _rough_fit(AttributionCfg().pattern_sweeps, truth)
    assert np.abs(th_lm - truth).max() > 0.01  # the stall this guards against
    assert np.abs(th - truth).max() < 0.002
    assert e < e_lm


def test_pattern_search_never_raises_the_energy_and_keeps_bounds() -> None:
    """A truth beyond the bounds: the search stops at the bound and returns a point no worse than its start."""
    from typing import cast

    from gmloco.deploy.mismatch.attribution import _pattern_search
    from gmloco.deploy.mismatch.effects import effect
    from gmloco.deploy.mismatch.problem import Problem

    spec = effect("sensor.encoder_offset")
    truth = np.full(12, 0.2)  # bounds are +-0.1 rad
    pb = _RoughBowl(spec.id, truth, amp=0.0)
    start = np.zeros(12)
    r0 = pb.resid({spec.id: start})
    theta, r = _pattern_search(cast(Problem, pb), spec, start, r0, sweeps=1)
    lo, hi = spec.bounds()
    assert np.all(theta >= lo) and np.all(theta <= hi)
    np.testing.assert_allclose(theta, hi)
    assert r @ r < r0 @ r0
    np.testing.assert_allclose(r, pb.resid({spec.id: theta}))


def test_workers_do_not_change_the_answer(delay_rec: object) -> None:
    """Screening and fits in two forked processes give the same numbers as one process, bit for bit."""
    from gmloco.deploy.mismatch.attribution import AttributionCfg, confirm, screen
    from gmloco.deploy.mismatch.problem import Problem, effective_samples
    from gmloco.deploy.mismatch.replay import ReplayCfg, Replayer

    pb = Problem(Replayer(delay_rec, ReplayCfg(horizon=12, stride=4)))  # type: ignore[arg-type]
    y0 = pb.simulate({})
    r0 = (pb.y - y0) / pb.sigma * pb.weight
    n_eff = effective_samples(r0[pb.train])
    out = []
    for workers in (1, 2):
        cfg = AttributionCfg(effects=("actuator.delay", "joint.armature", "imu.gyro_bias"), workers=workers, top_k=2)
        hyps = screen(pb, r0, y0, n_eff, cfg)
        ticks: list[int] = []
        ranked = confirm(pb, hyps, r0, cfg, partial(ticks.append, 1))
        assert len(ticks) == len(ranked) == 2  # one progress tick per finished fit
        out.append(([h.sens for h in hyps], [(h.spec.id, h.theta, h.ci, h.dbic) for h in ranked]))
    for a, b in zip(out[0][0], out[1][0], strict=True):
        np.testing.assert_array_equal(a, b)
    for (ia, ta, ca, da), (ib, tb, cb, db) in zip(out[0][1], out[1][1], strict=True):
        assert ia == ib and da == db
        np.testing.assert_array_equal(ta, tb)
        np.testing.assert_array_equal(ca, cb)


def test_progress_advances_per_fit_and_never_goes_back(delay_rec: Recording) -> None:
    """The progress callback names each stage, counts the fits, and its fraction only grows to 1."""
    seen: list[tuple[str, float]] = []
    analyze(delay_rec, _cfg(), lambda msg, frac: seen.append((msg, frac)))
    fracs = [f for _, f in seen]
    assert fracs == sorted(fracs) and fracs[-1] == 1.0
    msgs = [m for m, _ in seen]
    assert [m for m in msgs if m.startswith("confirmatory fits")] == [f"confirmatory fits ({i}/3)" for i in range(4)]
