# SPDX-License-Identifier: Apache-2.0
"""The benchmark scorer on hand-made rows (golden values computed by hand in the comments)."""

from __future__ import annotations

import numpy as np

from gmloco.deploy.mismatch.benchmark.scorer import score


def _row(effect: str, winner: str | None, verdict: str) -> dict:
    """A scored row as the sweep writes it."""
    return {"effect": effect, "strength": "mid" if effect != "none" else "none", "winner": winner, "verdict": verdict}


def test_scores_by_hand() -> None:
    """Two effect classes (one right, one wrong), four nulls (one named effect, one unexplained)."""
    right = _row("actuator.delay", "actuator.delay", "explained")
    right |= {
        "ranked": ["actuator.delay", "joint.armature"],
        "params": {"delay": [0.008]},
        "fit": {"delay": [0.009, 0.0085, 0.0095]},  # |0.009 - 0.008| / 0.008 = 0.125; CI misses 0.008
        "energy": {"nominal": 100.0, "oracle": 20.0, "fitted": 30.0},  # oracle fraction 70 / 80 = 0.875
    }
    wrong = _row("imu.gyro_bias", "joint.armature", "explained")
    wrong |= {
        "ranked": ["joint.armature", "imu.gyro_bias"],
        "params": {"bias": [0.03, 0.0, 0.0]},
        "energy": {"nominal": 100.0, "oracle": 95.0, "fitted": 100.0},  # oracle gain 0.05 < 0.1: not excited
    }
    nulls = [
        _row("none", None, "no_mismatch"),
        _row("none", None, "no_mismatch"),
        _row("none", "joint.armature", "explained"),
        _row("none", None, "unexplained"),
    ]
    s = score([right, wrong, *nulls])
    o = s["overall"]
    assert o["effect_classes_mid"] == 2
    np.testing.assert_allclose(o["top1_mid_macro"], 0.5)  # (1 + 0) / 2
    np.testing.assert_allclose(o["top3_mid_macro"], 1.0)  # both truths within the first three
    assert o["effect_classes_excited"] == 1 and o["not_excited"] == ["imu.gyro_bias@mid"]
    np.testing.assert_allclose(o["top1_mid_macro_excited"], 1.0)
    np.testing.assert_allclose(o["false_positive_rate_null"], 0.5)  # 2 of 4 not no_mismatch
    np.testing.assert_allclose(o["false_attribution_rate_null"], 0.25)  # 1 of 4 named an effect
    # Clopper-Pearson one-sided 95% upper bound for 2 / 4: beta.ppf(0.95, 3, 2) = 0.9024
    np.testing.assert_allclose(o["false_positive_upper95_null"], 0.9024, atol=1e-4)
    np.testing.assert_allclose(o["median_param_err_mid"], 0.125)
    np.testing.assert_allclose(o["ci_coverage_mid"], 0.0)
    np.testing.assert_allclose(s["per_effect"]["actuator.delay@mid"]["median_oracle_frac"], 0.875)


def test_config_patch_round_trips_to_flat_parameters() -> None:
    """A report's config patch maps back to the flat vector the replay takes (labels by component)."""
    from gmloco.deploy.mismatch.effects import effect, params_from_patch

    spec = effect("sensor.encoder_offset")
    labels = spec.labels()
    patch = {"sensor.encoder_offset": {labels[3]: 0.03, labels[6]: -0.03}, "actuator.delay": {"delay": 0.008}}
    p = params_from_patch(patch)
    expect = np.zeros(12)
    expect[3], expect[6] = 0.03, -0.03
    np.testing.assert_array_equal(p["sensor.encoder_offset"], expect)
    np.testing.assert_array_equal(p["actuator.delay"], [0.008])
