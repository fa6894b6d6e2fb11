# SPDX-License-Identifier: Apache-2.0
"""Exploration on tuning seeds only (399, 199, 198): refit the winner on posture-split training segments.

Splits the training segments at the median summed knee angle and compares the two fits with a Wald statistic
under the cluster-robust covariances. Not part of the tool; see ``STABILITY.md``.

    uv run python benchmarks/mismatch_benchmark/ool/stability_probe.py shank|enc|delay
"""

import sys
import time

import numpy as np

from gmloco.deploy.mismatch.attribution import AttributionCfg, _lm, _param_cov
from gmloco.deploy.mismatch.benchmark.episodes import MID
from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
from gmloco.deploy.mismatch.benchmark.truth import TruthEffect
from gmloco.deploy.mismatch.pipeline import AnalysisCfg, analyze
from gmloco.deploy.mismatch.problem import effective_samples

case = sys.argv[1]
eff = {
    "shank": TruthEffect("ool.shank_length", {"dl": [0.03]}),
    "enc": TruthEffect("sensor.encoder_offset", MID["sensor.encoder_offset"]),
    "delay": TruthEffect("actuator.delay", MID["actuator.delay"]),
}[case]
seed = {"shank": 399, "enc": 199, "delay": 198}[case]
wid = "actuator.delay" if case == "delay" else "sensor.encoder_offset"
t = time.time()
rec, _ = generate(EpisodeCfg(effect=eff, duration=9.0, seed=seed))
cfg = AnalysisCfg(attribution=AttributionCfg(effects=(wid, "joint.armature"), n_boot=100))
res = analyze(rec, cfg)
pb, w = res.arrays["problem"], res.arrays["winner"]
print(case, res.report["verdict"], res.report["winner"], "t", round(time.time() - t))
if w is None:
    sys.exit()
ki = [i for i, n in enumerate(rec.joint_names) if "knee" in n]
knee = rec.q[pb.starts][:, ki].sum(1)
train0 = pb.train.copy()
med = np.median(knee[train0])
ests = []
for part in (knee <= med, knee > med):
    pb.train = train0 & part
    theta, r, J = _lm(pb, w, cfg.attribution)
    n, k = r.size, w.spec.size
    n_eff = effective_samples(r.reshape(pb.y[pb.train].shape))
    s2 = float(r @ r) / max(n - k, 1) * (n / n_eff)
    cov, _ = _param_cov(J, r, pb.block[pb.train], s2)
    ests.append((theta, cov))
pb.train = train0
(t1, c1), (t2, c2) = ests
d = t1 - t2
W = float(d @ np.linalg.pinv(c1 + c2) @ d)
print("full", np.round(w.theta, 4))
print("low ", np.round(t1, 4))
print("high", np.round(t2, 4))
print(
    "wald",
    round(W, 1),
    "k",
    w.spec.size,
    "rel diff",
    round(float(np.linalg.norm(d) / max(np.linalg.norm(w.theta), 1e-12)), 3),
    "t",
    round(time.time() - t),
)
