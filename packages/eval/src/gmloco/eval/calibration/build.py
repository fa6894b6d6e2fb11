# SPDX-License-Identifier: Apache-2.0
"""Build a calibration dataset: run the sole experiments of one material on a sand and write the versioned file."""

from __future__ import annotations

import subprocess
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, RftExtensionsCfg
from gmloco.eval.calibration.dataset import CalibrationDataset, assign_split, save_dataset
from gmloco.eval.calibration.mpm_sand import MpmSoleSandCfg, mpm_sole_smoke_cfg
from gmloco.eval.calibration.protocol import EXPERIMENTS, PROBE_EXPERIMENTS, SoleProtocolCfg, SoleSand, run_experiment

__all__ = ["CalibrationBuildCfg", "build_dataset", "smoke_build_cfg"]


@dataclass(frozen=True)
class CalibrationBuildCfg:
    """What to run and where to write it."""

    material: str = "dry_sand"
    """Medium: a ``gmloco.contact.MATERIAL_PRESETS`` name."""
    out_dir: str = "results/sand_calibration/dataset"
    """Folder of ``<material>.npz``."""
    sand: Literal["mpm", "rft3d_reference"] = "mpm"
    """Sand simulator: Newton MPM (the judge) or the float64 3D-RFT reference (synthetic data, tests)."""
    experiments: tuple[str, ...] = EXPERIMENTS
    """Experiments to run."""
    split_seed: int = 0
    """Seed of the fit / held-out split, drawn before any fitting."""
    heldout_fraction: float = 0.4
    """Share of the records held out [-]."""
    protocol: SoleProtocolCfg = field(default_factory=SoleProtocolCfg)
    """Sole, loads, speeds, frame time."""
    mpm: MpmSoleSandCfg = field(default_factory=MpmSoleSandCfg)
    """MPM bed and numerics (``sand="mpm"``)."""
    reference_extensions: RftExtensionsCfg = field(default_factory=RftExtensionsCfg)
    """Extension terms of the reference sand (``sand="rft3d_reference"``): known parameters for synthetic data."""
    reference_resolution: int = 3
    """Cells per edge of the reference sand's sole box."""


def smoke_build_cfg(
    material: str, out_dir: str, sand: Literal["mpm", "rft3d_reference"] = "mpm"
) -> CalibrationBuildCfg:
    """Return a CPU smoke configuration: tiny bed, coarse voxels, phases shortened 10x."""
    return CalibrationBuildCfg(material=material, out_dir=out_dir, sand=sand, mpm=mpm_sole_smoke_cfg(),
                               protocol=SoleProtocolCfg(time_scale=0.1, max_press_time=1.0))  # fmt: skip


def _git_commit() -> str:
    """Return the current git commit (provenance), or ``"unknown"`` outside a checkout."""
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def _make_sand(cfg: CalibrationBuildCfg) -> tuple[SoleSand, Any]:
    """Return a fresh sand for one experiment and the object to read timings from (None for the reference)."""
    material = MATERIAL_PRESETS[cfg.material]
    if cfg.sand == "mpm":
        from gmloco.eval.calibration.mpm_sand import MpmSoleSand

        sand = MpmSoleSand(cfg.mpm, cfg.protocol, material)
        return sand, sand
    from gmloco.eval.calibration.rft_sand import centred_sole_collider, rft_sole_sand

    ext = replace(cfg.reference_extensions, dt=cfg.protocol.frame_dt)
    model = ContactRFT3DCfg(at_rest="none", extensions=ext)
    collider = centred_sole_collider(cfg.protocol, "box", cfg.reference_resolution)
    return rft_sole_sand(collider, model, material), None


def build_dataset(cfg: CalibrationBuildCfg) -> tuple[Path, dict[str, Any]]:
    """Run every experiment on a fresh bed, split the records by seed and write ``<out_dir>/<material>.npz``.

    Returns the file and the timings [s] (build and stepping per experiment, total).
    """
    if cfg.material not in MATERIAL_PRESETS:
        raise ValueError(f"unknown material {cfg.material!r}: choose from {sorted(MATERIAL_PRESETS)}")
    unknown = set(cfg.experiments) - set(EXPERIMENTS + PROBE_EXPERIMENTS)
    if unknown:
        raise ValueError(f"unknown experiments {sorted(unknown)}: choose from {EXPERIMENTS + PROBE_EXPERIMENTS}")
    t_all = time.perf_counter()
    records, timings = {}, {}
    for name in cfg.experiments:
        t0 = time.perf_counter()
        sand, mpm = _make_sand(cfg)
        records[name] = run_experiment(name, cfg.protocol, sand)
        if mpm is not None:
            mpm.check()
            timings[name] = {"build_s": mpm.build_s, "step_s": mpm.step_s, "frames": len(records[name].time),
                             "particle_count": mpm.particle_count}  # fmt: skip
        else:
            timings[name] = {"total_s": time.perf_counter() - t0, "frames": len(records[name].time)}
    timings["total_s"] = time.perf_counter() - t_all
    mat = MATERIAL_PRESETS[cfg.material]
    ds = CalibrationDataset(
        material=cfg.material,
        material_params={"rho_c": mat.rho_c, "mu_int": mat.mu_int, "mu_surf": mat.mu_surf},
        source=cfg.sand,
        protocol=cfg.protocol,
        records=records,
        split=assign_split(list(records), cfg.split_seed, cfg.heldout_fraction),
        split_seed=cfg.split_seed,
        extra={"git_commit": _git_commit(), "timings": timings, "mpm": asdict(cfg.mpm) if cfg.sand == "mpm" else None,
               "reference_extensions": asdict(cfg.reference_extensions) if cfg.sand != "mpm" else None},
    )  # fmt: skip
    return save_dataset(ds, Path(cfg.out_dir) / f"{cfg.material}.npz"), timings
