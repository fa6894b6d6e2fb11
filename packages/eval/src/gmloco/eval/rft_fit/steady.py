# SPDX-License-Identifier: Apache-2.0
"""Steady resistive stress per depth of one plate run: alpha = F / (A d), G = alpha / xi_n (spec section 8, step 3)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gmloco.eval.rft_fit.fit import rft3d_invariants
from gmloco.eval.rft_fit.plate import PlateIntrusionCfg, PlateRun

__all__ = ["DEPTH_BINS", "plate_direction", "plate_record", "steady_alpha"]

DEPTH_BINS = 3
"""Depth bins of the per-depth stress profile of a run."""


def plate_direction(gamma_deg: float, beta_deg: float, psi_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Return (plate normal [3], velocity direction [3]) for PNAS-style angles.

    gamma: intrusion angle below the horizontal (90 = straight down); the velocity lies in the x-z plane.
    beta: tilt of the normal from -z; psi: heading of the tilt relative to the velocity's horizontal direction.
    """
    g, b, p = (math.radians(a) for a in (gamma_deg, beta_deg, psi_deg))
    v = np.array([math.cos(g), 0.0, -math.sin(g)])
    n = np.array([math.sin(b) * math.cos(p), math.sin(b) * math.sin(p), -math.cos(b)])
    # exact zeros: cos(90 deg) = 6e-17 would otherwise decide the n_z = 0 tie of spec 1.1 step 2 (which flips)
    n[np.abs(n) < 1e-12] = 0.0
    v[np.abs(v) < 1e-12] = 0.0
    return n, v


def steady_alpha(run: PlateRun, area: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Return (alpha [N/m^3] [3], median of F/(A d) [3], relative RMS residual of F = alpha A d) over the window.

    RFT: a flat plate at uniform orientation feels F = alpha A d_c (d_c: centroid depth), so alpha is the
    least-squares slope of F against A d_c through the origin (less noisy than a per-frame ratio: the MPM
    force oscillates as the plate crosses voxel faces).
    """
    idx = np.flatnonzero(run.sampled)
    if len(idx) == 0:
        return np.full(3, np.nan), np.full(3, np.nan), float("nan")
    ad = area * run.depth[idx]
    f = run.force[idx]
    alpha = (ad @ f) / (ad @ ad)
    ratio = np.median(f / ad[:, None], axis=0)
    resid = f - np.outer(ad, alpha)
    rel = float(np.sqrt(np.sum(resid**2) / max(np.sum(f**2), 1e-300)))
    return alpha, ratio, rel


def _alpha_by_depth(run: PlateRun, area: float) -> dict[str, list]:
    """Return the mean F/(A d) [N/m^3] in ``DEPTH_BINS`` equal depth bins of the steady window."""
    idx = np.flatnonzero(run.sampled)
    if len(idx) < DEPTH_BINS:
        return {"depth": [], "alpha": []}
    bins = np.array_split(idx[np.argsort(run.depth[idx])], DEPTH_BINS)
    return {
        "depth": [round(float(run.depth[b].mean()), 4) for b in bins],
        "alpha": [np.round(np.mean(run.force[b] / (area * run.depth[b, None]), axis=0), 1).tolist() for b in bins],
    }


def plate_record(
    run: PlateRun, plate: PlateIntrusionCfg, xi: float, angles: tuple[float, float, float], mu_plate: float,
    friction_tol: float,
) -> dict[str, Any]:  # fmt: skip
    """Return the JSON record of one run: direction, invariants, steady alpha and G, friction flag, timing, series.

    A sample is ``friction_limited`` when its tangential stress reaches ``friction_tol`` x the plate friction
    times its normal stress: there the RFT surface-friction cap (spec 1.1 step 7) and not G_t sets the force.
    """
    area = plate.plate_size**2
    n_lead = run.normal if run.normal @ run.velocity >= 0 else -run.normal
    alpha, ratio, rel = steady_alpha(run, area)
    x, _, _ = rft3d_invariants(n_lead[None], run.velocity[None])
    a_n = float(alpha @ n_lead)
    a_t = float(np.linalg.norm(alpha - a_n * n_lead))
    limited = bool(np.isfinite(a_n) and a_t >= friction_tol * mu_plate * abs(a_n))
    return {
        "gamma_deg": angles[0], "beta_deg": angles[1], "psi_deg": angles[2],
        "normal": run.normal.tolist(), "velocity_dir": (run.velocity / np.linalg.norm(run.velocity)).tolist(),
        "leading_normal": n_lead.tolist(), "x": x[0].round(6).tolist(),
        "alpha": alpha.tolist(), "G": (alpha / xi).tolist(), "G_median_ratio": (ratio / xi).tolist(),
        "linear_rel_rms": rel, "samples": int(run.sampled.sum()), "friction_ratio": a_t / max(abs(a_n), 1e-12),
        "friction_limited": limited, "mu_plate": mu_plate, "alpha_by_depth": _alpha_by_depth(run, area),
        "wall_s": run.wall_time, "frames_per_s": run.frames_per_s, "particle_count": run.particle_count,
        "frames": len(run.depth), "depth_series": np.round(run.depth, 5).tolist(),
        "force_series": np.round(run.force, 2).tolist(), "sampled": run.sampled.astype(int).tolist(),
    }  # fmt: skip
