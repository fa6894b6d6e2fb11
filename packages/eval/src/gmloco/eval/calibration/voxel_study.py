# SPDX-License-Identifier: Apache-2.0
"""Voxel-size study of the MPM sole response: the same calibration experiments at several voxel sizes; bad input exits 2.

Per material and voxel size (read from each dataset's MPM solver settings) it reports the press force-depth curve,
the depth at which the sole carries the single-stance G1 weight, the force at fixed depths, the onset height (how
far above the nominal bed top the sole first carries ``onset_fraction`` of the weight), the drag lateral force, the
lift-off suction and the depth growth over the repeated steps; per material, the relative change of the depth at
the weight and of the force at fixed depths from each voxel size to the next finer one. Model-free: no fit is run.

python -m gmloco.eval.calibration.voxel_study --datasets results/sand_calibration/dataset/voxel_1cm
        results/sand_calibration/dataset results/sand_calibration/dataset/voxel_3cm
        --out results/sand_calibration/voxel_study/summary.json
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.atomic_io import atomic_write_json
from gmloco.eval.calibration.dataset import CalibrationDataset, ContractError, load_dataset
from gmloco.eval.calibration.protocol import SoleRecord, experiment_phases
from gmloco.eval.calibration.summary import depth_at_force

__all__ = ["VoxelStudyCfg", "build_voxel_study", "dataset_voxel_size", "material_response"]

MATERIALS: tuple[str, ...] = ("dry_sand", "poppy_seed", "basalt")
"""Materials of the calibration datasets."""


@dataclass(frozen=True)
class VoxelStudyCfg:
    """Read-outs and thresholds of the voxel study."""

    materials: tuple[str, ...] = MATERIALS
    """Materials to read (``<material>.npz`` in every dataset folder)."""
    onset_fraction: float = 0.02
    """Share of the single-stance weight that counts as first non-trivial force [-] (0.02: 6.9 N for the G1)."""
    depths: tuple[float, ...] = (0.005, 0.01, 0.02, 0.04, 0.08)
    """Depths of the sole's lowest point at which the press force is compared [m] (below the top: the force at the
    top itself is the onset's business, and its relative change is ill-posed)."""
    converged_change: float = 0.2
    """Largest relative change to the next finer voxel size that counts as converged [-]."""
    min_depth: float = 0.002
    """Smallest |depth| [m] a relative depth change is taken of (below it: null, the absolute change stays)."""
    figures: bool = True
    """Write ``force_depth_by_voxel.png`` beside the JSON."""


def dataset_voxel_size(ds: CalibrationDataset) -> float:
    """Return the MPM voxel size [m] a dataset was made at (ContractError if it records none)."""
    try:
        return float((ds.extra or {})["mpm"]["solver"]["voxel_size"])
    except (KeyError, TypeError) as e:
        raise ContractError(
            "voxel_size", f"{ds.material} dataset records no MPM voxel size (source {ds.source})"
        ) from e


def _phase_index(name: str, ds: CalibrationDataset, kind: str, which: int = 0) -> int:
    """Return the index of the ``which``-th phase of ``kind`` in experiment ``name``."""
    hits = [k for k, p in enumerate(experiment_phases(name, ds.protocol)) if p.kind == kind]
    return hits[which]


def _press(rec: SoleRecord) -> tuple[np.ndarray, np.ndarray]:
    """Return depth [m] and vertical force [N] of the first (press) phase, each [T0]."""
    first = rec.phase == 0
    return rec.depth[first], rec.force[first, 2]


def _force_at(depth: np.ndarray, fz: np.ndarray, d: float) -> float | None:
    """Return F_z [N] at depth ``d`` [m] (linear between frames), None outside the pressed range."""
    if not len(depth) or d < depth[0] or d > depth[-1]:
        return None
    return float(np.interp(d, depth, fz))


def _onset(depth: np.ndarray, fz: np.ndarray, threshold: float) -> dict[str, Any]:
    """Return the height above the nominal top [m] where F_z first reaches ``threshold`` [N].

    ``censored``: the first frame already carries it, so the felt surface is at least that high (the start gap).
    """
    d = depth_at_force(depth, fz, threshold)
    return {"height_m": None if d is None else -d, "censored": bool(len(fz) and fz[0] >= threshold)}


def _drag(ds: CalibrationDataset, name: str) -> dict[str, float] | None:
    """Return mean |F_xy| and F_z [N] over the second half of the drag move, and their ratio [-]."""
    rec = ds.records.get(name)
    if rec is None:
        return None
    move = np.nonzero(rec.phase == _phase_index(name.removesuffix("_fast"), ds, "move"))[0]
    window = move[len(move) // 2 :]
    lateral = float(np.mean(np.hypot(rec.force[window, 0], rec.force[window, 1])))
    vertical = float(np.mean(rec.force[window, 2]))
    return {"lateral_N": lateral, "vertical_N": vertical, "lateral_over_vertical": lateral / max(vertical, 1e-9)}


def _liftoff(ds: CalibrationDataset, threshold: float) -> dict[str, float | None] | None:
    """Return the suction (largest downward sand force while lifting) [N] and the lift until F_z < threshold [m]."""
    rec = ds.records.get("liftoff")
    if rec is None:
        return None
    lift = rec.phase == _phase_index("liftoff", ds, "move")
    fz, depth = rec.force[lift, 2], rec.depth[lift]
    free = np.nonzero(fz < threshold)[0]
    release = float(depth[0] - depth[free[0]]) if len(free) else None
    return {"suction_N": float(max(0.0, -fz.min(initial=0.0))), "release_lift_m": release}


def _repeat(ds: CalibrationDataset, load: float) -> dict[str, Any] | None:
    """Return the depth at the weight [m] of each step into one footprint and its growth (last - first) [m]."""
    rec = ds.records.get("repeat")
    if rec is None:
        return None
    presses = [k for k, p in enumerate(experiment_phases("repeat", ds.protocol)) if p.kind == "press"]
    depths = [depth_at_force(rec.depth[rec.phase == k], rec.force[rec.phase == k, 2], load) for k in presses]
    first, last = depths[0], depths[-1]
    growth = last - first if first is not None and last is not None else None
    return {"depths_at_weight_m": depths, "growth_m": growth}


def material_response(ds: CalibrationDataset, cfg: VoxelStudyCfg) -> dict[str, Any]:
    """Return the model-free sole response of one dataset (see the module docstring); depths [m], forces [N]."""
    if "press" not in ds.records:
        raise ContractError("experiments", f"{ds.material} dataset has no press record")
    weight = ds.protocol.weight
    depth, fz = _press(ds.records["press"])
    timings = (ds.extra or {}).get("timings", {})
    at_weight, onset = depth_at_force(depth, fz, weight), _onset(depth, fz, cfg.onset_fraction * weight)
    return {
        "voxel_size_m": dataset_voxel_size(ds),
        "particle_count": timings.get("press", {}).get("particle_count"),
        "weight_N": weight,
        "weight_depth_m": at_weight,
        "press_max_force_N": float(fz.max(initial=0.0)),
        "force_at_depth_N": {f"{d:g}": _force_at(depth, fz, d) for d in cfg.depths},
        "onset": onset,
        "felt_weight_depth_m": None
        if at_weight is None or onset["height_m"] is None
        else at_weight + onset["height_m"],
        "drag": _drag(ds, "drag"),
        "drag_fast": _drag(ds, "drag_fast"),
        "liftoff": _liftoff(ds, cfg.onset_fraction * weight),
        "repeat": _repeat(ds, weight),
        "press_curve": {"depth_m": np.round(depth, 5).tolist(), "force_z_N": np.round(fz, 2).tolist()},
    }


def _rel(coarse: float | None, fine: float | None, floor: float = 0.0) -> float | None:
    """Return (coarse - fine) / |fine| [-], None when either is missing or |fine| <= ``floor``."""
    if coarse is None or fine is None or abs(fine) <= floor:
        return None
    return (coarse - fine) / abs(fine)


def _pair_change(coarse: dict[str, Any], fine: dict[str, Any], cfg: VoxelStudyCfg) -> dict[str, Any]:
    """Return the change of the depth at the weight and of the force at fixed depths from ``fine`` to ``coarse``."""
    dc, df = coarse["weight_depth_m"], fine["weight_depth_m"]
    forces = {d: _rel(coarse["force_at_depth_N"][d], f, 1e-9) for d, f in fine["force_at_depth_N"].items()}
    return {
        "weight_depth_change_m": None if dc is None or df is None else dc - df,
        "weight_depth_rel_change": _rel(dc, df, cfg.min_depth),
        "force_rel_change_at_depth": forces,
    }


def _convergence(by_voxel: dict[str, dict[str, Any]], cfg: VoxelStudyCfg) -> dict[str, Any]:
    """Return the changes from each voxel size to every finer one, and whether the two finest agree."""
    keys = sorted(by_voxel, key=float)
    pairs = {
        f"{c}_vs_{f}": _pair_change(by_voxel[c], by_voxel[f], cfg) for i, f in enumerate(keys) for c in keys[i + 1 :]
    }
    out: dict[str, Any] = {"pairs": pairs, "finest_pair": None, "finest_pair_converged": None}
    if len(keys) >= 2:
        finest = pairs[f"{keys[1]}_vs_{keys[0]}"]
        changes = [finest["weight_depth_rel_change"], *finest["force_rel_change_at_depth"].values()]
        known = [abs(c) for c in changes if c is not None]
        out["finest_pair"] = f"{keys[1]}_vs_{keys[0]}"
        out["finest_pair_converged"] = bool(max(known) <= cfg.converged_change) if known else None
    return out


def build_voxel_study(folders: list[str], out: str | Path, cfg: VoxelStudyCfg) -> dict[str, Any]:
    """Read ``<material>.npz`` from each folder (one voxel size a folder), write the study JSON; return it."""
    body: dict[str, Any] = {"materials": {}, "convergence": {}, "inputs": {}}
    for mat in cfg.materials:
        by_voxel: dict[str, dict[str, Any]] = {}
        for folder in folders:
            path = Path(folder) / f"{mat}.npz"
            ds = load_dataset(path)
            if ds.material != mat:
                raise ContractError("material", f"{path} holds material {ds.material!r}, not {mat!r}")
            key = f"{dataset_voxel_size(ds):g}"
            if key in by_voxel:
                raise ValueError(f"two {mat} datasets at voxel size {key} m: give one folder per voxel size")
            by_voxel[key] = material_response(ds, cfg)
            body["inputs"][f"{mat}@{key}"] = str(path)
        body["materials"][mat] = dict(sorted(by_voxel.items(), key=lambda kv: float(kv[0])))
        body["convergence"][mat] = _convergence(by_voxel, cfg)
    body["settings"] = asdict(cfg)
    body["notes"] = _NOTES
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    body["figures"] = [str(_figure(body, out.parent / "force_depth_by_voxel.png"))] if cfg.figures else []
    atomic_write_json(out, body, allow_nan=False, newline=True)
    return body


_NOTES: dict[str, str] = {
    "keys": "materials.<material>.<voxel size [m]>; depths [m] of the sole's lowest point below the nominal bed top",
    "weight_depth_m": "depth where the press first carries the single-stance G1 weight (linear between frames); "
    "null: the press never carried it",
    "felt_weight_depth_m": "weight_depth_m + onset.height_m: depth at the weight below the surface the sole first "
    "feels (a lower bound where the onset is censored)",
    "onset": "height_m: height above the nominal bed top where the press first carries onset_fraction of the "
    "weight; censored: already carried at the first frame (start gap 5 mm), so the felt surface is at least that high",
    "drag": "mean over the second half of the 0.1 m/s (drag_fast: 0.4 m/s) move at half the weight's press depth",
    "liftoff": "suction_N: largest downward sand force while lifting at 0.1 m/s; release_lift_m: lift until F_z "
    "falls below onset_fraction of the weight",
    "repeat": "depth at the weight of each of the three steps into one footprint; growth_m = last - first",
    "convergence": "pairs '<coarse>_vs_<fine>': (coarse - fine) / |fine|; null where a value is missing or "
    "|fine depth| < min_depth",
}
"""What each key of the study means."""


def _figure(body: dict[str, Any], path: Path) -> Path:
    """Write press F_z [N] against depth [cm], one panel per material, one line per voxel size."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mats = list(body["materials"])
    fig, axes = plt.subplots(1, len(mats), figsize=(4.0 * len(mats), 3.4), squeeze=False)
    for ax, mat in zip(axes.flat, mats, strict=True):
        weight = 0.0
        for key, row in body["materials"][mat].items():
            curve = row["press_curve"]
            ax.plot(100.0 * np.asarray(curve["depth_m"]), curve["force_z_N"], lw=1.2, label=f"{100 * float(key):g} cm")
            weight = row["weight_N"]
        ax.axhline(weight, color="k", ls="--", lw=0.8, label="G1 weight")
        ax.axvline(0.0, color="0.6", lw=0.6)
        ax.set(title=mat, xlabel="depth of the sole's lowest point [cm]", ylabel="vertical sand force [N]")
        ax.legend(title="MPM voxel", fontsize=7)
    fig.suptitle("MPM sole press by voxel size (G1 sole, 5 cm/s)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    """Parse the command line."""
    p = argparse.ArgumentParser(
        prog="python -m gmloco.eval.calibration.voxel_study", description=(__doc__ or "").splitlines()[0]
    )
    p.add_argument("--datasets", nargs="+", required=True, help="dataset folders, one voxel size each")
    p.add_argument("--out", default="results/sand_calibration/voxel_study/summary.json")
    p.add_argument("--materials", nargs="+", default=list(MATERIALS))
    p.add_argument("--onset-fraction", type=float, default=0.02, help="share of the weight that marks the onset [-]")
    p.add_argument("--no-figures", action="store_true")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Build and write the voxel study; return the exit code (2: bad input)."""
    a = parse_args(argv)
    try:
        if not 0.0 < a.onset_fraction < 1.0:
            raise ValueError(f"--onset-fraction {a.onset_fraction} must lie in (0, 1)")
        cfg = VoxelStudyCfg(tuple(a.materials), a.onset_fraction, figures=not a.no_figures)
        body = build_voxel_study(a.datasets, a.out, cfg)
    except (ContractError, FileNotFoundError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    for mat, rows in body["materials"].items():
        for key, row in rows.items():
            d = row["weight_depth_m"]
            print(f"{mat:11s} {key:>5s} m  depth at weight {'-' if d is None else f'{100 * d:.2f} cm'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
