# SPDX-License-Identifier: Apache-2.0
"""Calibrate the model floors of a welded pelvis (``FloorCfg.fixed_base``) on fixed-base chirp nulls.

Usage::

    python -m gmloco.deploy.mismatch.benchmark.fixed_floor --seeds 300 301 302 303 --duration 4

Each null is a joint chirp on a gantry (:mod:`.chirp`) with nuisances and sensor noise, no hidden effect. Per
signal group g, the model floor ``m_g`` solves ``mean_c,k (y - y_sim)^2 / (sigma_meas_c^2 + m_g^2) = 1`` over
the nulls' shooting segments (bisection; 0 when the measurement noise alone already gives energy below one), as
the free-base floors were set on their nulls.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

__all__ = ["calibrate", "main"]


def _solve(raw2: np.ndarray, meas2: np.ndarray) -> float:
    """Model floor ``m`` with ``mean(raw2 / (meas2 + m^2)) = 1`` (bisection on log m), 0 if already below one."""
    energy = lambda m: float(np.mean(raw2 / (meas2 + m * m)))  # noqa: E731
    if energy(0.0) <= 1.0:
        return 0.0
    lo, hi = 1e-9, float(np.sqrt(raw2.mean())) + 1e-9
    for _ in range(100):
        mid = np.sqrt(lo * hi)
        lo, hi = (mid, hi) if energy(mid) > 1.0 else (lo, mid)
    return float(hi)


def calibrate(seeds: list[int], duration: float) -> dict[str, float]:
    """Return the per-group model floors of a welded pelvis from chirp nulls with the given seeds."""
    from gmloco.deploy.mismatch.benchmark.chirp import ChirpCfg
    from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
    from gmloco.deploy.mismatch.problem import FloorCfg, Problem
    from gmloco.deploy.mismatch.replay import CHANNEL_GROUPS, Replayer

    zero = FloorCfg(fixed_base=dict.fromkeys(FloorCfg().fixed_base, 0.0))
    raw2: dict[str, list[np.ndarray]] = {g: [] for g, _ in CHANNEL_GROUPS}
    meas2: dict[str, list[np.ndarray]] = {g: [] for g, _ in CHANNEL_GROUPS}
    for seed in seeds:
        rec, _ = generate(EpisodeCfg(duration=duration, seed=seed, support="gantry", chirp=ChirpCfg(duration=duration)))
        pb = Problem(Replayer(rec), zero)
        d2 = (pb.y - pb.simulate({})) ** 2
        off = 0
        for g, w in CHANNEL_GROUPS:
            cols = slice(off, off + w)
            raw2[g].append(d2[..., cols].reshape(-1, w))
            meas2[g].append(np.broadcast_to(pb.sigma[cols] ** 2, (d2.shape[0] * d2.shape[1], w)))
            off += w
    return {g: _solve(np.concatenate(raw2[g]), np.concatenate(meas2[g])) for g, _ in CHANNEL_GROUPS}


def main(argv: list[str] | None = None) -> None:
    """Print the calibrated floors as JSON."""
    p = argparse.ArgumentParser(prog="fixed_floor", description=__doc__)
    p.add_argument("--seeds", type=int, nargs="+", default=[300, 301, 302, 303])
    p.add_argument("--duration", type=float, default=4.0, help="length of each null [s]")
    a = p.parse_args(argv)
    print(json.dumps({"seeds": a.seeds, "duration_s": a.duration, "floors": calibrate(a.seeds, a.duration)}))


if __name__ == "__main__":
    main()
