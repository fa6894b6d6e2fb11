# SPDX-License-Identifier: Apache-2.0
"""RFT from MPM: plate-intrusion sweep over (x1, x2, x3), steady G per run, 60-coefficient fit, comparison.

``run(cfg)`` is resumable and time-boxed like the box study: each finished plate run is appended to
``plate_runs.jsonl`` and skipped on the next call; the fit uses every run done so far.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.eval.rft_fit.fit import fit_rft3d_coeffs, generic_from_coeffs, rft3d_invariants, save_rft3d_coeffs
from gmloco.eval.rft_fit.plate import PlateIntrusionCfg, PlateRun, run_plate_intrusion

__all__ = ["RftFitCfg", "plate_directions", "rft_fit_smoke_cfg", "run", "steady_generic"]

SPEC_CASES: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "A_sole_down": ((0, 0, -1), (0, 0, -1)),
    "B_sole_diag": ((0, 0, -1), (1, 0, -1)),
    "D_sole_shallow": ((0, 0, -1), (1, 0, -0.1)),
    "E_toe_down": ((0.5, 0, -0.866), (0, 0, -1)),
    "F_heel_strike": ((-0.5, 0, -0.866), (1, 0, -1)),
    "G_wall": ((1, 0, 0), (1, 0, 0)),
    "H_top_up": ((0, 0, 1), (0, 0, 1)),
}
"""(normal, velocity) of the spec's table-5.1 cases, for comparing fitted and published G."""


@dataclass(frozen=True)
class RftFitCfg:
    """Configuration of the MPM plate sweep and the coefficient fit."""

    out_dir: str = "results/rft_fit"
    """Output directory (plate_runs.jsonl, rft3d_fitted.json, fit_summary.json)."""
    material: str = "dry_sand"
    """Medium: a ``gmloco.contact.MATERIAL_PRESETS`` name."""
    plate: PlateIntrusionCfg = field(default_factory=PlateIntrusionCfg)
    """Plate, bed and MPM numerics."""
    gamma_deg: tuple[float, ...] = (90.0, 60.0, 30.0, 0.0, -30.0, -60.0)
    """Intrusion angles below the horizontal [deg] (90 = straight down, negative = upward): spans x1."""
    beta_deg: tuple[float, ...] = (0.0, 30.0, 60.0, 90.0)
    """Plate tilts of the normal from -z [deg]: spans x2."""
    psi_deg: tuple[float, ...] = (0.0, 90.0, 180.0)
    """Headings of the tilted normal relative to the velocity's horizontal direction [deg]: spans x3 and G_theta."""
    min_leading_cos: float = 0.1
    """Skip near edge-on runs with |n . v_hat| below this [-]."""
    ridge: float = 1e-3
    """Tikhonov weight towards the prior set (constrains directions the sweep leaves open) [-]."""
    prior: str = "pnas"
    """Prior / comparison coefficient set of the contact package."""
    max_minutes: float = 60.0
    """Wall-clock budget [min]."""


def rft_fit_smoke_cfg(out_dir: str) -> RftFitCfg:
    """Return a CPU smoke configuration: 2 runs, 0.3 x 0.3 x 0.16 m bed at 4 cm voxels, a short path."""
    from gmloco.eval.mpm.bed import SandBedCfg
    from gmloco.eval.mpm.box_scene import MpmSolverCfg

    plate = PlateIntrusionCfg(
        plate_size=0.08, plate_thickness=0.02, speed=0.3, depth_range=(0.05, 0.08), travel_before_sampling=0.03,
        bed=SandBedCfg(size_x=0.3, size_y=0.3, depth=0.16, center_x=0.0),
        solver=MpmSolverCfg(voxel_size=0.04, max_iterations=20), device="cpu",
    )  # fmt: skip
    return RftFitCfg(out_dir=out_dir, plate=plate, gamma_deg=(90.0, 0.0), beta_deg=(0.0,), psi_deg=(0.0,))


def plate_directions(cfg: RftFitCfg) -> list[tuple[np.ndarray, np.ndarray]]:
    """Return the sweep's (plate normal, velocity direction) pairs, edge-on pairs removed."""
    pairs = []
    for gamma in np.radians(cfg.gamma_deg):
        v = np.array([math.cos(gamma), 0.0, -math.sin(gamma)])
        for beta in np.radians(cfg.beta_deg):
            for psi in np.radians(cfg.psi_deg) if beta > 0 else [0.0]:
                n = np.array([math.sin(beta) * math.cos(psi), math.sin(beta) * math.sin(psi), -math.cos(beta)])
                if abs(n @ v) >= cfg.min_leading_cos:
                    pairs.append((n, v))
    return pairs


def steady_generic(run: PlateRun, plate: PlateIntrusionCfg, xi: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Return (leading normal [3], median G over the steady window [3], sample count).

    alpha = F / (A d_c) per frame (RFT: F = alpha A d_c for a flat plate at uniform orientation), G = alpha / xi.
    """
    n_lead = run.normal if run.normal @ run.velocity >= 0 else -run.normal
    idx = np.flatnonzero(run.sampled)
    area = plate.plate_size**2
    g = run.force[idx] / (area * run.depth[idx, None]) / xi
    return n_lead, np.median(g, axis=0) if len(idx) else np.full(3, np.nan), len(idx)


def _done_runs(path: Path) -> list[dict[str, Any]]:
    """Read the finished plate runs (a torn last line is ignored)."""
    if not path.exists():
        return []
    out = []
    for line in path.read_text().splitlines():
        try:
            out.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return out


def _sweep(cfg: RftFitCfg, material: Any, xi: float, log: Path, t_start: float) -> bool:
    """Run the missing plate intrusions; return False if the time budget stopped the sweep."""
    done = {(tuple(np.round(r["normal"], 6)), tuple(np.round(r["velocity_dir"], 6))) for r in _done_runs(log)}
    last = 0.0
    for n, v in plate_directions(cfg):
        if (tuple(np.round(n, 6)), tuple(np.round(v, 6))) in done:
            continue
        if time.perf_counter() - t_start + last > 60.0 * cfg.max_minutes:
            return False
        res = run_plate_intrusion(cfg.plate, material, n, v)
        last = res.wall_time
        n_lead, g, count = steady_generic(res, cfg.plate, xi)
        rec = {"normal": n.tolist(), "velocity_dir": v.tolist(), "leading_normal": n_lead.tolist(), "G": g.tolist(),
               "samples": count, "wall_s": res.wall_time, "particle_count": res.particle_count,
               "frames": len(res.depth), "force_mean": res.force[res.sampled].mean(0).tolist() if count else None}  # fmt: skip
        with log.open("a") as f:
            f.write(json.dumps(rec) + "\n")
    return True


def run(cfg: RftFitCfg) -> dict[str, Any]:
    """Run (or resume) the sweep, fit the coefficients, compare with the prior set, write the outputs."""
    from gmloco.contact import MATERIAL_PRESETS, RFT3D_COEFFS

    t_start = time.perf_counter()
    out = Path(cfg.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "config.json").write_text(json.dumps(asdict(cfg), indent=1, default=str))
    material = MATERIAL_PRESETS[cfg.material]
    complete = _sweep(cfg, material, material.xi, out / "plate_runs.jsonl", t_start)
    all_runs = _done_runs(out / "plate_runs.jsonl")
    # a run whose plate felt no force at all is a failed coupling, not data (README, "Known issue")
    runs = [r for r in all_runs if r["samples"] > 0 and np.all(np.isfinite(r["G"])) and np.any(np.abs(r["G"]) > 0)]
    summary: dict[str, Any] = {"complete": complete, "runs_done": len(all_runs), "runs_used": len(runs),
                               "runs_zero_force": sum(1 for r in all_runs if not np.any(np.abs(r["G"]) > 0)),
                               "material": asdict(material), "xi_n": material.xi}  # fmt: skip
    if runs:
        nrm = np.array([r["leading_normal"] for r in runs])
        vel = np.array([r["velocity_dir"] for r in runs])
        g = np.array([r["G"] for r in runs])
        prior = RFT3D_COEFFS[cfg.prior]
        fit = fit_rft3d_coeffs(nrm, vel, g, ridge=cfg.ridge, prior=prior)
        g_prior = generic_from_coeffs(prior, nrm, vel)
        x, _, _ = rft3d_invariants(nrm, vel)
        cases_n = np.array([c[0] for c in SPEC_CASES.values()], dtype=float)
        cases_v = np.array([c[1] for c in SPEC_CASES.values()], dtype=float)
        cases_n /= np.linalg.norm(cases_n, axis=1, keepdims=True)
        summary.update({
            "fit_residual_rms": fit.residual_rms, "fit_relative_residual": fit.relative_residual,
            "design_rank": fit.rank, "ridge": cfg.ridge,
            f"{cfg.prior}_residual_rms": float(np.sqrt(np.mean((g_prior - g) ** 2))),
            f"{cfg.prior}_relative_residual": float(np.linalg.norm(g_prior - g) / np.linalg.norm(g)),
            "coeff_max_abs_diff_vs_prior": float(np.max(np.abs(fit.coeffs - prior))),
            "x_range": {"min": x.min(0).tolist(), "max": x.max(0).tolist()},
            "cases_G_fitted": dict(zip(SPEC_CASES, generic_from_coeffs(fit.coeffs, cases_n, cases_v).round(4).tolist(), strict=True)),
            f"cases_G_{cfg.prior}": dict(zip(SPEC_CASES, generic_from_coeffs(prior, cases_n, cases_v).round(4).tolist(), strict=True)),
            "plate_wall_s_median": float(np.median([r["wall_s"] for r in runs])),
            "particle_count": int(max(r["particle_count"] for r in runs)),
        })  # fmt: skip
        save_rft3d_coeffs(out / "rft3d_fitted.json", fit.coeffs, {"material": cfg.material, "runs": len(runs),
                          "residual_rms": fit.residual_rms, "ridge": cfg.ridge, "prior": cfg.prior,
                          "voxel_size": cfg.plate.solver.voxel_size, "source": "gmloco.eval.rft_fit (MPM plate sweep)"})  # fmt: skip
    summary["wall_s_this_run"] = time.perf_counter() - t_start
    (out / "fit_summary.json").write_text(json.dumps(summary, indent=1))
    return summary
