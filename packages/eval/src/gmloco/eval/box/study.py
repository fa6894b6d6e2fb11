# SPDX-License-Identifier: Apache-2.0
"""Box-intrusion study: reduced-order models vs Newton implicit MPM over randomized media (issue 5).

``run(cfg)`` samples ``num_trials`` media (seeded), simulates the box under every model and both launch variants,
appends one record per (variant, trial, model) to ``out_dir`` (resumable: done records are skipped), stops
cleanly after ``max_minutes`` and then writes ``summary.json`` and the figure from whatever is done.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from gmloco.eval.box.config import BoxCfg, box_lateral_variant, box_roll_variant, box_size_variant
from gmloco.eval.box.rom import ROM_MODELS, RomBoxCfg, simulate_rom_box
from gmloco.eval.metrics.box import metric_lateral_force, metric_sinkage, metric_travel
from gmloco.eval.mpm.bed import SandBedCfg
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.studies.study_io import StudyRecords

__all__ = ["MEDIA_DRAWS", "MPM_FAILURES", "BoxStudyCfg", "box_study_smoke_cfg", "run", "sample_media"]

MPM_FAILURES = "mpm_failures.jsonl"
MPM_WARNINGS = "mpm_warnings.jsonl"
"""Per failed MPM solve: variant, trials, error and ``MpmBoxScene.diagnostics()`` (one JSON line each)."""
MEDIA_DRAWS = 1024
"""Draws per medium parameter from the study seed; trial t uses draw t whatever the number of trials."""


@dataclass(frozen=True)
class BoxStudyCfg:
    """Configuration of the box-intrusion study."""

    out_dir: str = "results/box_intrusion"
    """Output directory (trials.csv, grf.jsonl.gz, summary.json, fig_box_intrusion.png)."""
    num_trials: int = 30
    """Number of randomized media N (N >= 30 for the paper figure)."""
    seed: int = 0
    """Seed of the media sampling."""
    bulk_density: tuple[float, float] = (1000.0, 3000.0)
    """Uniform range of the grain density [kg/m^3] (GM-Loco DR)."""
    packing: tuple[float, float] = (0.5, 1.0)
    """Uniform range of the packing ratio [-]; rho_c = packing * bulk_density (GM-Loco DR)."""
    mu_int: tuple[float, float] = (0.2, 0.9)
    """Uniform range of mu_int [-] (GM-Loco code DR)."""
    mu_surf: tuple[float, float] = (0.1, 1.0)
    """Uniform range of mu_surf [-] (GM-Loco DR)."""
    variants: tuple[str, ...] = ("forward", "lateral")
    """Launch variants: ``forward`` (box aligned with its velocity), ``lateral`` (box yawed 30 deg), ``roll`` (box
    rolled 15 deg about its launch direction: the lateral-force case only 3D models resolve), and for the
    box-size check ``size_x<scale>`` (e.g. ``size_x0.7``: the forward box with its footprint scaled, same mass)."""
    models: tuple[str, ...] = ("mpm", *ROM_MODELS)
    """Models to run; ``rft3d_fitted`` is added automatically when ``rft3d_fitted_coeffs`` is set."""
    box: BoxCfg = field(default_factory=BoxCfg)
    """The forward-variant box."""
    rom: RomBoxCfg = field(default_factory=RomBoxCfg)
    """Reduced-order numerics (its ``box`` is replaced per variant)."""
    bed: SandBedCfg = field(default_factory=SandBedCfg)
    """MPM sand bed."""
    mpm: MpmSolverCfg = field(default_factory=lambda: MpmSolverCfg(voxel_size=0.03, max_iterations=250))
    """MPM numerics (voxel size and rheology iterations from the convergence check). 250 iterations is Newton's
    default; Newton's coupled example uses 50, at which a plate's resistance is 40 % below its 800-iteration value
    (README)."""
    rft3d_fitted_coeffs: str = ""
    """Optional fitted 3D-RFT coefficient file (``results/rft_fit/rft3d_fitted.json``) run as ``rft3d_fitted``."""
    max_minutes: float = 60.0
    """Wall-clock budget [min]; the runner stops before an MPM trial it expects to overrun."""
    device: str | None = None
    """Warp device of the MPM side; None = Warp's default (CUDA when present)."""
    mpm_batch: int = 1
    """MPM trials per solve (one walled region each, ``MpmBoxScene`` batching); ~10 on a GPU, 1 on a CPU."""
    rigid_solver: Literal["mujoco", "semi_implicit"] = "semi_implicit"
    """Box integrator of the MPM scene (``MpmBoxSceneCfg.rigid_solver``): the same free-body equations either way
    (checked in the tests); ``semi_implicit`` avoids building mujoco_warp for every trial on a GPU."""
    make_figure: bool = True
    """Write ``fig_box_intrusion.png`` at the end."""
    mpm_max_leaked_fraction: float = 1.0e-4
    """Stray particles below the floor a trial may leave, per region, as a fraction of its particles (``test_final``);
    tolerated ones are logged to ``mpm_warnings.jsonl``. 2 cm voxels lost 1-5 of 288k in 3 of 30 trials."""


def box_study_smoke_cfg(out_dir: str, **overrides: Any) -> BoxStudyCfg:
    """Return a CPU smoke configuration: 1 trial, a 0.6 x 0.5 x 0.2 m bed at 5 cm voxels, 0.2 s (impact included)."""
    box = BoxCfg(duration=0.2)
    cfg = BoxStudyCfg(
        out_dir=out_dir,
        num_trials=1,
        variants=("forward",),
        box=box,
        rom=RomBoxCfg(box=box, collider_resolution=3),
        bed=SandBedCfg(size_x=0.6, size_y=0.5, depth=0.2, center_x=0.1),
        mpm=MpmSolverCfg(voxel_size=0.05, max_iterations=30),
        device="cpu",
        make_figure=False,
    )
    return replace(cfg, **overrides)


def sample_media(cfg: BoxStudyCfg) -> dict[str, np.ndarray]:
    """Sample the trials' media, each [num_trials]: bulk_density, packing, rho_c, mu_int, mu_surf.

    Trial t's medium does not depend on ``num_trials`` (the first ``MEDIA_DRAWS`` draws per parameter are
    sliced), so studies of different sizes with one seed share their first trials (convergence and size checks).
    """
    rng = np.random.default_rng(cfg.seed)
    n = cfg.num_trials
    if n > MEDIA_DRAWS:
        raise ValueError(f"num_trials={n} > {MEDIA_DRAWS}")
    keys = ("bulk_density", "packing", "mu_int", "mu_surf")
    media = {k: rng.uniform(*getattr(cfg, k), size=MEDIA_DRAWS)[:n] for k in keys}
    media["rho_c"] = media["packing"] * media["bulk_density"]
    return media


def _variant_box(cfg: BoxStudyCfg, variant: str) -> BoxCfg:
    """Return the box of a launch variant."""
    if variant == "forward":
        return cfg.box
    if variant == "lateral":
        return box_lateral_variant(cfg.box)
    if variant == "roll":
        return box_roll_variant(cfg.box)
    if variant.startswith("size_x"):
        try:
            scale = float(variant.removeprefix("size_x"))
        except ValueError:
            scale = -1.0
        if scale > 0.0:
            return box_size_variant(cfg.box, scale)
    raise ValueError(
        f"variant={variant!r}: expected 'forward', 'lateral', 'roll' or 'size_x<scale>' (e.g. 'size_x0.7')"
    )


def _record(
    cfg: BoxStudyCfg, variant: str, trial: int, model: str, media: dict[str, np.ndarray], traj: dict[str, np.ndarray],
    box: BoxCfg, timing: dict[str, float],
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:  # fmt: skip
    """Build one CSV row and its series from a trajectory (pos [T,3], quat_wxyz [T,4], grf [T,3], time [T])."""
    row: dict[str, Any] = {"variant": variant, "trial": trial, "model": model}
    row.update({k: round(float(media[k][trial]), 6) for k in ("bulk_density", "packing", "rho_c", "mu_int", "mu_surf")})
    row["travel"] = metric_travel(traj["pos"], box.initial_pos)
    row["sinkage"] = metric_sinkage(traj["pos"][-1], traj["quat_wxyz"][-1], box.half_extents[2])
    row["lateral_force"] = metric_lateral_force(traj["grf"], box.velocity)
    row["peak_fz"] = float(np.max(traj["grf"][:, 2]))
    row.update(timing)
    return row, {"time": traj["time"], "grf": traj["grf"], "pos": traj["pos"]}


def _run_rom(cfg: BoxStudyCfg, records: StudyRecords, media: dict[str, np.ndarray], models: list[str]) -> None:
    """Run every reduced-order model on all trials of every variant that has a missing record."""
    done = records.done()
    for variant in cfg.variants:
        box = _variant_box(cfg, variant)
        for model in models:
            missing = [t for t in range(cfg.num_trials) if records.key(variant, t, model) not in done]
            if model == "mpm" or not missing:
                continue
            rom_cfg = replace(cfg.rom, box=box)
            if model == "rft3d_fitted":
                rom_cfg = replace(rom_cfg, rft3d_coeffs=cfg.rft3d_fitted_coeffs)
            res = simulate_rom_box(
                model.removesuffix("_fitted"), rom_cfg, *(media[k] for k in ("rho_c", "mu_int", "mu_surf"))
            )
            n_frames = res.time.shape[0]
            timing = {"wall_s": res.wall_time / cfg.num_trials, "frames_per_s": n_frames * cfg.num_trials / res.wall_time,
                      "particle_count": 0, "voxel_size": 0.0}  # fmt: skip
            for t in missing:
                traj = {"pos": res.body_pos[t], "quat_wxyz": res.body_quat[t], "grf": res.grf[t], "time": res.time}
                records.append(*_record(cfg, variant, t, model, media, traj, box, timing))


def _run_mpm_batch(
    cfg: BoxStudyCfg, variant: str, box: BoxCfg, media: dict[str, np.ndarray], trials: list[int]
) -> list[tuple[dict, dict]]:
    """Simulate trials in one MPM solve (one walled region per trial); return each trial's trajectory and timing.

    A solve that fails its physical checks (``MpmBoxScene.test_final``) appends its diagnostics to
    ``MPM_FAILURES`` in the output directory and re-raises.

    Timing per trial: ``wall_s`` = the batch's wall time / its trials, ``frames_per_s`` = the batch's frames per
    second, ``particle_count`` = particles of one region.
    """
    # here, not at the top: gmloco.contact pulls Warp; this module imports with numpy alone
    from gmloco.contact import MaterialCfg
    from gmloco.eval.mpm.box_scene import MpmBoxScene, MpmBoxSceneCfg

    keys = ("bulk_density", "packing", "mu_int", "mu_surf")
    mats = [MaterialCfg(*(float(media[k][t]) for k in keys)) for t in trials]
    t0 = time.perf_counter()
    scene_cfg = MpmBoxSceneCfg(box=box, bed=cfg.bed, solver=cfg.mpm, device=cfg.device, rigid_solver=cfg.rigid_solver)
    scene = MpmBoxScene(scene_cfg, mats)
    scene.run()
    try:
        diag = scene.test_final(cfg.mpm_max_leaked_fraction)
    except AssertionError as e:
        # keep what a failed solve tells (which region, how far, how many particles) for the report
        diag = {"variant": variant, "trials": trials, "error": str(e), "media": [asdict(m) for m in mats],
                **scene.diagnostics()}  # fmt: skip
        with (Path(cfg.out_dir) / MPM_FAILURES).open("a") as f:
            f.write(json.dumps(diag, default=float) + "\n")
        raise
    if diag["leaked_particles"]:  # within the tolerance: kept, and said
        with (Path(cfg.out_dir) / MPM_WARNINGS).open("a") as f:
            f.write(json.dumps({"variant": variant, "trials": trials, **diag}, default=float) + "\n")
    q_all, f_all = np.array(scene.body_q_all), np.array(scene.sand_force_all)  # [T, R, 7] (p, q_xyzw), [T, R, 3]
    timing = {"wall_s": (time.perf_counter() - t0) / len(trials), "frames_per_s": scene.frames_per_second,
              "particle_count": scene.particle_count // len(trials), "voxel_size": cfg.mpm.voxel_size}  # fmt: skip
    out = []
    for i in range(len(trials)):
        q = q_all[:, i]
        traj = {"pos": q[:, :3] - scene.offsets[i], "quat_wxyz": q[:, [6, 3, 4, 5]], "grf": f_all[:, i],
                "time": cfg.mpm.frame_dt * np.arange(1, len(q) + 1)}  # fmt: skip
        out.append((traj, timing))
    return out


def _run_mpm(cfg: BoxStudyCfg, records: StudyRecords, media: dict[str, np.ndarray], t_start: float) -> bool:
    """Run the missing MPM trials in batches of ``mpm_batch``; return False if the time budget stopped them."""
    last_batch_s = 0.0
    for variant in cfg.variants:
        box = _variant_box(cfg, variant)
        done = records.done()
        todo = [t for t in range(cfg.num_trials) if records.key(variant, t, "mpm") not in done]
        for i in range(0, len(todo), cfg.mpm_batch):
            if time.perf_counter() - t_start + 1.2 * last_batch_s > 60.0 * cfg.max_minutes:
                return False
            batch = todo[i : i + cfg.mpm_batch]
            t0 = time.perf_counter()
            try:
                results = _run_mpm_batch(cfg, variant, box, media, batch)
            except AssertionError:
                results = []  # logged in MPM_FAILURES; the other batches still run (use --mpm-batch 1 to isolate)
            for trial, (traj, timing) in zip(batch if results else [], results, strict=True):
                records.append(*_record(cfg, variant, trial, "mpm", media, traj, box, timing))
            last_batch_s = time.perf_counter() - t0
    return True


# Settings that change a record's numbers: a directory's records must all share them (``check_resume``).
RESULT_FIELDS = ("seed", "bulk_density", "packing", "mu_int", "mu_surf", "box", "rom", "bed", "mpm", "rigid_solver")


def _flatten(value: Any, prefix: str) -> dict[str, Any]:
    """Return ``{dotted.path: leaf}`` of a JSON-like value."""
    if isinstance(value, dict):
        out: dict[str, Any] = {}
        for k, v in value.items():
            out.update(_flatten(v, f"{prefix}.{k}"))
        return out
    return {prefix: value}


def check_resume(cfg: BoxStudyCfg, records: StudyRecords) -> None:
    """Refuse to add records to a directory whose records were made under other settings.

    A resumed study skips the records it finds, so a call with, e.g., another box duration would silently mix two
    studies in one table. Compares the fields of ``RESULT_FIELDS`` (device excepted) with the directory's
    ``config.json``; the fitted 3D-RFT set may be added to a directory without one, never swapped.
    """
    saved_path = Path(cfg.out_dir) / "config.json"
    if not saved_path.exists() or not records.rows():
        return
    saved = json.loads(saved_path.read_text())
    new = json.loads(json.dumps(asdict(cfg), default=str))
    old_flat: dict[str, Any] = {}
    new_flat: dict[str, Any] = {}
    for key in RESULT_FIELDS:
        old_flat.update(_flatten(saved.get(key), key))
        new_flat.update(_flatten(new.get(key), key))
    diffs = [
        f"{k}: directory {old_flat.get(k)!r}, this call {new_flat.get(k)!r}"
        for k in sorted(set(old_flat) | set(new_flat))
        if not k.endswith(".device") and old_flat.get(k) != new_flat.get(k)
    ]
    old_fit, new_fit = saved.get("rft3d_fitted_coeffs"), new.get("rft3d_fitted_coeffs")
    if old_fit and new_fit and old_fit != new_fit:
        diffs.append(f"rft3d_fitted_coeffs: directory {old_fit!r}, this call {new_fit!r}")
    if diffs:
        raise ValueError(
            f"{cfg.out_dir} holds records made under other settings, and a resumed study would mix them:\n  "
            + "\n  ".join(diffs)
            + f"\nPass the directory's settings ({saved_path}) or choose a new out_dir."
        )


def run(cfg: BoxStudyCfg) -> dict[str, Any]:
    """Run (or resume) the study and write its outputs; return the summary with a ``complete`` flag."""
    from gmloco.eval.box.summary import summarize_study

    t_start = time.perf_counter()
    records = StudyRecords(cfg.out_dir)
    check_resume(cfg, records)
    media = sample_media(cfg)
    models = list(cfg.models) + (["rft3d_fitted"] if cfg.rft3d_fitted_coeffs else [])
    (Path(cfg.out_dir) / "config.json").write_text(json.dumps(asdict(cfg), indent=1, default=str))
    _run_rom(cfg, records, media, models)
    complete = _run_mpm(cfg, records, media, t_start) if "mpm" in models else True
    # MPM is the reference of every score, also when this call only adds reduced-order models
    summary = summarize_study(records, cfg, models if "mpm" in models else ["mpm", *models])
    from gmloco.eval.box.checks import lateral_impact_summary, size_sensitivity

    if any(v.startswith("size_x") for v in cfg.variants):
        summary["size_sensitivity"] = size_sensitivity(summary)
    velocities = {v: _variant_box(cfg, v).velocity for v in cfg.variants}
    summary["lateral_impact"] = lateral_impact_summary(records, velocities, cfg.box.mass * 9.81)
    failures = Path(cfg.out_dir) / MPM_FAILURES
    if failures.exists():
        lines = [json.loads(ln) for ln in failures.read_text().splitlines() if ln.strip()]
        keys = ("variant", "trials", "error", "leaked_particles", "leaked_per_region", "particle_z_min", "box_z")
        summary["mpm_failures"] = [{k: f.get(k) for k in keys} for f in lines]
    if "mpm" in models:  # failed solves leave their trials without records
        done = records.done()
        complete = complete and all(
            records.key(v, t, "mpm") in done for v in cfg.variants for t in range(cfg.num_trials)
        )
    summary["complete"] = complete
    summary["wall_s_this_run"] = time.perf_counter() - t_start
    (Path(cfg.out_dir) / "summary.json").write_text(json.dumps(summary, indent=1))
    if cfg.make_figure and records.rows():
        from gmloco.eval.box.figure import fig_box_intrusion

        fig_box_intrusion(records, cfg.box.mass, Path(cfg.out_dir) / "fig_box_intrusion.png")
        from gmloco.eval.box.checks import fig_lateral_impact

        fig_lateral_impact(records, velocities, cfg.box.mass * 9.81, Path(cfg.out_dir) / "fig_lateral_impact.png")
    return summary
