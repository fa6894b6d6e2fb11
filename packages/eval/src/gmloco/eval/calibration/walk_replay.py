# SPDX-License-Identifier: Apache-2.0
"""How sand models answer the feet of recorded MPM walks: each model replays the walks' own sole kinematics.

A walk dataset (:mod:`gmloco.eval.calibration.walk_records`) holds, per foot and 50 Hz frame, where the sole box was,
how it moved and the force MPM's sand put on it. Every model (the published 3D-RFT always, fitted terms with
``--model LABEL=FILE``) replays the same kinematics with a fresh memory per foot, at the datum (the height of the
surface the sole feels above the bed's nominal top) that fits the walks' fit split best with the model's terms held:
MPM's grid carries a sole up to a voxel above the nominal top, and on a flat bed a datum is only a shift of the
surface, which the training simulator's flat sand leaves out. Per model: the RMS force error per split [N]; per bin of the sole's horizontal speed and
depth (submerged frames only), the mean vertical force and horizontal force magnitude of MPM and of each model [N],
which says where a model is too stiff or too soft::

    python -m gmloco.eval.calibration.walk_replay --dataset results/sand_calibration/dataset/walks/dry_sand.npz \
        --model calibrated=results/sand_calibration/rft3d_calibrated.json --out results/sand_calibration/walk_replay

writes ``summary.json`` and ``fig_walk_forces.png`` into ``--out``. Exit codes: 0 written, 2 bad input (no dataset,
a dataset of sole experiments, a bad model argument).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.contact import RftExtensionsCfg
from gmloco.contact.extensions_io import load_rft_extensions
from gmloco.deploy.atomic_io import atomic_write_json
from gmloco.eval.calibration.dataset import CalibrationDataset, load_dataset
from gmloco.eval.calibration.fit import SandFitCfg, fit_datum, replay_forces, rms_by_split

__all__ = ["DEPTH_EDGES_M", "SPEED_EDGES_MPS", "binned_forces", "main", "walk_replay"]

SPEED_EDGES_MPS: tuple[float, ...] = (0.0, 0.2, 0.5, 1.0, float("inf"))
"""Bins of the sole centre's horizontal speed [m/s]: planted to sliding fast."""
DEPTH_EDGES_M: tuple[float, ...] = (0.005, 0.03, 0.06, 0.30)
"""Bins of the sole's lowest-corner depth below the bed top [m]; shallower frames are left out."""


def _stack(ds: CalibrationDataset, field: str, names: list[str]) -> np.ndarray:
    """One record field of every named record, frames concatenated."""
    return np.concatenate([getattr(ds.records[n], field) for n in names])


def binned_forces(depth: np.ndarray, speed: np.ndarray, forces: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    """Return one row per (speed, depth) bin with frames: ``n`` and per source mean ``fz`` and ``fxy`` [N].

    Args:
        depth: Sole depth per frame [m], [T].
        speed: Horizontal speed of the sole centre per frame [m/s], [T].
        forces: Force per frame [N], [T, 3], by source (``"mpm"`` and each model's label).
    """
    rows = []
    for lo, hi in pairwise(SPEED_EDGES_MPS):
        for dlo, dhi in pairwise(DEPTH_EDGES_M):
            sel = (speed >= lo) & (speed < hi) & (depth >= dlo) & (depth < dhi)
            if not sel.any():
                continue
            row: dict[str, Any] = {"speed_mps": [lo, hi if np.isfinite(hi) else None], "depth_m": [dlo, dhi],
                                   "n": int(sel.sum())}  # fmt: skip
            for label, f in forces.items():
                row[label] = {"fz": float(f[sel, 2].mean()), "fxy": float(np.hypot(f[sel, 0], f[sel, 1]).mean())}
            rows.append(row)
    return rows


def walk_replay(ds: CalibrationDataset, models: dict[str, RftExtensionsCfg], cfg: SandFitCfg) -> dict[str, Any]:
    """Return the summary of the module docstring for the walks of ``ds`` and ``models`` (published one added).

    Keys: ``dataset``, ``models`` (their terms), ``datum_m`` (each model's fitted datum [m]), ``rms_force_error_N``
    (per split, at that datum) and ``bins`` (:func:`binned_forces`).
    """
    models = {"published": RftExtensionsCfg(), **models}
    names = list(ds.records)
    vel = _stack(ds, "lin_vel", names)
    depth, speed = _stack(ds, "depth", names), np.hypot(vel[:, 0], vel[:, 1])
    forces = {"mpm": _stack(ds, "force", names)}
    errors, datums = {}, {}
    for label, ext in models.items():
        datums[label] = fit_datum(ds, ext, cfg)
        replay = replay_forces(ds, ext, cfg, names, datums[label])
        forces[label] = np.concatenate([replay[n] for n in names])
        errors[label] = rms_by_split(ds, {n: np.sum((replay[n] - ds.records[n].force) ** 2, -1) for n in names})
    known = np.isfinite(forces["mpm"]).all(axis=1)  # frames with MPM's force (momentum records: single support)
    return {
        "dataset": {
            "material": ds.material,
            "records": len(names),
            "frames": len(depth),
            "frames_with_force": int(known.sum()),
            "force_source": (ds.extra or {}).get("walk_records", {}).get("force_source", "logged"),
            "submerged_frames": (depth >= DEPTH_EDGES_M[0]).sum().item(),
            "frame_dt_s": ds.protocol.frame_dt,
            "recordings": (ds.extra or {}).get("recordings"),
        },
        "models": {label: asdict(ext) for label, ext in models.items()},
        "datum_m": datums,
        "rms_force_error_N": errors,
        "bins": binned_forces(depth[known], speed[known], {k: f[known] for k, f in forces.items()}),
    }


def _figure(summary: dict[str, Any], path: Path) -> None:
    """Mean vertical (top) and horizontal (bottom) force by depth bin, one panel per speed bin."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    bins = summary["bins"]
    speeds = sorted({tuple(b["speed_mps"][:1]) for b in bins})
    sources = ["mpm", *summary["models"]]
    fig, axes = plt.subplots(2, len(speeds), figsize=(3.2 * len(speeds), 5.6), sharey="row", squeeze=False)
    for j, (lo,) in enumerate(speeds):
        rows = [b for b in bins if b["speed_mps"][0] == lo]
        x = [100.0 * 0.5 * (b["depth_m"][0] + b["depth_m"][1]) for b in rows]
        for src in sources:
            style = {"color": "k", "lw": 2.5} if src == "mpm" else {"lw": 1.2, "marker": "o", "ms": 3}
            for i, key in enumerate(("fz", "fxy")):
                axes[i, j].plot(x, [b[src][key] for b in rows], label=src, **style)
        hi = rows[0]["speed_mps"][1]
        axes[0, j].set_title(f"|v_xy| {lo:g}-{hi:g} m/s" if hi is not None else f"|v_xy| > {lo:g} m/s", fontsize=9)
        axes[1, j].set_xlabel("sole depth [cm]")
    axes[0, 0].set_ylabel("mean F_z [N]")
    axes[1, 0].set_ylabel("mean |F_xy| [N]")
    axes[0, -1].legend(fontsize=7)
    fig.suptitle(f"{summary['dataset']['material']}: MPM walks' sole forces and models on the same kinematics",
                 fontsize=10)  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _models(specs: list[str]) -> dict[str, RftExtensionsCfg]:
    """Parse ``LABEL=FILE`` arguments (ValueError naming the bad one)."""
    out = {}
    for spec in specs:
        label, sep, file = spec.partition("=")
        if not sep or not label or not file:
            raise ValueError(
                f"--model {spec!r}: give LABEL=FILE, e.g. calibrated=results/sand_calibration/rft3d_calibrated.json"
            )
        if label in out or label in ("mpm", "published"):
            raise ValueError(f"--model {spec!r}: label {label!r} is taken")
        if not Path(file).is_file():
            raise ValueError(f"--model {spec!r}: no file {file}")
        out[label] = load_rft_extensions(file)
    return out


def main(argv: list[str] | None = None) -> int:
    """Command line of the module docstring (exit 2 on bad input)."""
    p = argparse.ArgumentParser(
        prog="python -m gmloco.eval.calibration.walk_replay", description=(__doc__ or "").split("\n")[0]
    )
    p.add_argument("--dataset", required=True, help="walk dataset from python -m gmloco.eval.calibration.walk_records")
    p.add_argument("--model", action="append", default=[], help="LABEL=FILE of fitted RftExtensionsCfg (repeatable)")
    p.add_argument("--out", required=True, help="folder for summary.json and fig_walk_forces.png")
    args = p.parse_args(argv)
    try:
        ds = load_dataset(args.dataset)
        if (ds.extra or {}).get("kind") != "walks":
            raise ValueError(f"{args.dataset} holds sole experiments, not walks: build one with walk_records")
        models = _models(args.model)
    except (FileNotFoundError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    summary = walk_replay(ds, models, SandFitCfg())
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_json(out / "summary.json", summary)
    _figure(summary, out / "fig_walk_forces.png")
    for label, err in summary["rms_force_error_N"].items():
        print(f"{label}: RMS force error fit {err['fit']:.1f} N, held-out {err['heldout']:.1f} N")
    print(f"-> {out / 'summary.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
