# SPDX-License-Identifier: Apache-2.0
"""A loaded sole under shear: MPM's twist, drag and re-press records against 3D-RFT models.

The ``twist`` experiment presses the G1 sole to the single-stance load, holds it, then turns it +a, -2a, +a about
the vertical at a constant depth. Per record this reads the load before the turn and, for each of the three turns,
the mean yaw torque [N m] (its sign opposes the turn when the sand resists), its peak magnitude, and the vertical
force left at the turn's end: a sand that yields under the twist loses its support. Each model (the published
3D-RFT and fitted extension terms) replays the same kinematics at the datum fitted for it on the same material's
dataset (the height of the surface the sole feels; see :mod:`gmloco.eval.calibration.fit`), so a stiff medium the
sole barely enters is compared where the model carries load at all::

    python -m gmloco.eval.calibration.shear --dataset results/sand_calibration/dataset/with_twist/dry_sand.npz
        --model calibrated=results/sand_calibration/rft3d_calibrated.json --out results/sand_calibration/shear

writes ``summary.json`` and ``fig_twist.png`` there (exit 2 on a dataset without a twist record or a bad model).

The ``drag`` record asks the same of a slide: the sole, pressed to half the load and held, moves 10 cm sideways at
constant depth and rests again. :func:`drag_response` reads the load before the slide, the mean horizontal force
during it and the support left in the rest after it (``fig_drag.png``): a sand whose support returns when the sole
stops forgets the slide; one whose support stays low keeps it.

``--probes`` names datasets of the probe experiments (``protocol.PROBE_EXPERIMENTS``: the loaded sole slides 5 cm
or turns, rests, and is pressed again until the sand carries the load). :func:`resupport_response` reads the extra
depth the second press needed; each model runs the same experiment closed-loop on its own sand (its extra depth is
its own, no replay), into ``summary.json``'s ``probes`` and ``fig_resupport.png``. ``--predict MATERIAL`` writes
each model's probe responses with no MPM record (``probe_predictions``): a prediction made before the MPM probes
are recorded.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, MaterialCfg, RftExtensionsCfg
from gmloco.contact.extensions_io import load_rft_extensions
from gmloco.deploy.atomic_io import atomic_write_json
from gmloco.eval.calibration.dataset import CalibrationDataset, load_dataset
from gmloco.eval.calibration.fit import SandFitCfg, dataset_material, fit_datum, held_terms, replay_wrenches
from gmloco.eval.calibration.protocol import PROBE_EXPERIMENTS, SoleProtocolCfg, SoleRecord, run_experiment
from gmloco.eval.calibration.rft_sand import centred_sole_collider, rft_sole_sand

__all__ = [
    "DRAG_PHASES",
    "TURN_PHASES",
    "drag_response",
    "main",
    "predict_probes",
    "resupport_response",
    "twist_response",
]

TURN_PHASES: tuple[int, int, int] = (2, 3, 4)
"""Phase indices of the three turns in a twist record (0 press, 1 hold)."""
DRAG_PHASES: tuple[int, int, int] = (1, 2, 3)
"""Phase indices of a drag record's hold before the slide, the slide and the rest after it (0 the press)."""
RECORD = "twist"
DRAG = "drag"


def twist_response(force: np.ndarray, torque_z: np.ndarray, phase: np.ndarray) -> dict[str, Any]:
    """Return the twist's load and per-turn response of one sand.

    Args:
        force: Sand force on the sole [N], [T, 3].
        torque_z: Yaw torque about the sole centre [N m], [T].
        phase: Phase index per frame, [T] (1 the hold, :data:`TURN_PHASES` the turns).

    Returns:
        ``load_N`` (mean F_z over the hold) and per turn (``turn_1``..``turn_3``): ``torque_mean_Nm``,
        ``torque_peak_Nm`` (largest magnitude), ``force_z_end_N`` (F_z at the turn's last frame) and
        ``support_kept`` (that over the load).
    """
    hold = phase == 1
    if not hold.any() or not all((phase == k).any() for k in TURN_PHASES):
        raise ValueError("not a twist record: it needs a hold phase (1) and three turns (phases 2-4)")
    load = float(np.mean(force[hold, 2]))
    out: dict[str, Any] = {"load_N": load}
    for i, k in enumerate(TURN_PHASES, start=1):
        sel = phase == k
        tz = torque_z[sel]
        out[f"turn_{i}"] = {
            "torque_mean_Nm": float(np.mean(tz)),
            "torque_peak_Nm": float(tz[np.argmax(np.abs(tz))]),
            "force_z_end_N": float(force[sel, 2][-1]),
            "support_kept": float(force[sel, 2][-1] / load) if load > 0.0 else float("nan"),
        }
    return out


def drag_response(force: np.ndarray, phase: np.ndarray) -> dict[str, float]:
    """Return the load before a drag record's slide, its drag force and the support left after it.

    Args:
        force: Sand force on the sole [N], [T, 3].
        phase: Phase index per frame, [T] (:data:`DRAG_PHASES`: hold, slide, rest).

    Returns:
        ``load_N`` (mean F_z of the hold), ``drag_force_N`` (mean horizontal force magnitude during the slide),
        ``force_z_end_of_slide_N``, ``support_after_N`` (mean F_z of the rest) and ``support_kept`` (that over the
        load).
    """
    before, slide, after = (phase == k for k in DRAG_PHASES)
    if not (before.any() and slide.any() and after.any()):
        raise ValueError("not a drag record: it needs a hold (1), a slide (2) and a rest (3)")
    load = float(np.mean(force[before, 2]))
    support = float(np.mean(force[after, 2]))
    return {
        "load_N": load,
        "drag_force_N": float(np.mean(np.hypot(force[slide, 0], force[slide, 1]))),
        "force_z_end_of_slide_N": float(force[slide, 2][-1]),
        "support_after_N": support,
        "support_kept": support / load if load > 0.0 else float("nan"),
    }


def resupport_response(
    depth: np.ndarray, force: np.ndarray, phase: np.ndarray, target_load: float | None = None
) -> dict[str, Any]:
    """Return what re-pressing a sole after a slide or a turn took (phases: press, hold, move, rest, press, hold).

    Args:
        depth: Depth of the sole's lowest point [m], [T].
        force: Sand force on the sole [N], [T, 3].
        phase: Phase index per frame, [T] (the second press may have no frame: the sand already carried the load).
        target_load: The presses' target [N] (the protocol's weight); None leaves ``loaded`` out.

    Returns:
        ``load_N`` (mean F_z of the first hold), ``support_after_move_N`` (mean F_z of the rest after the move),
        ``depth_loaded_m`` and ``depth_reloaded_m`` (mean depths of the two holds), ``extra_depth_m`` (their
        difference), ``reloaded`` (whether the last hold carries 95 % of the first one's load) and, with
        ``target_load``, ``loaded`` (whether the first press reached 95 % of it: a sand that cannot carry the load
        makes both presses run to their time limit, and the extra depth then measures nothing).
    """
    first, rest, last = phase == 1, phase == 3, phase == 5
    if not (first.any() and rest.any() and last.any()):
        raise ValueError("not a probe record: it needs holds at phases 1, 3 and 5 (see protocol.PROBE_EXPERIMENTS)")
    load = float(np.mean(force[first, 2]))
    d0, d1 = float(np.mean(depth[first])), float(np.mean(depth[last]))
    return {
        "load_N": load,
        "support_after_move_N": float(np.mean(force[rest, 2])),
        "depth_loaded_m": d0,
        "depth_reloaded_m": d1,
        "extra_depth_m": d1 - d0,
        "reloaded": bool(np.mean(force[last, 2]) >= 0.95 * load),
        **({} if target_load is None else {"loaded": bool(load >= 0.95 * target_load)}),
    }


def _model_probe(
    protocol: SoleProtocolCfg, material: MaterialCfg, name: str, ext: RftExtensionsCfg, cfg: SandFitCfg
) -> SoleRecord:
    """Run probe ``name`` closed-loop on a model's float64 sand (``protocol``'s sole and frame time, ``material``)."""
    model = ContactRFT3DCfg(at_rest=cfg.at_rest, extensions=replace(ext, dt=protocol.frame_dt))
    sand = rft_sole_sand(centred_sole_collider(protocol, "box", cfg.resolution), model, material)
    return run_experiment(name, protocol, sand)


def predict_probes(materials: list[str], models: dict[str, tuple[RftExtensionsCfg, str]], cfg: SandFitCfg) -> dict:
    """Return each model's probe responses per material at the default protocol, with no MPM record needed.

    Written before the MPM probes are recorded, this is the models' prediction, to be held against them.
    """
    out: dict[str, Any] = {}
    for mat in materials:
        if mat not in MATERIAL_PRESETS:
            raise ValueError(f"unknown material {mat!r}: choose from {sorted(MATERIAL_PRESETS)}")
        for name in PROBE_EXPERIMENTS:
            for label, (ext, _) in models.items():
                run = _model_probe(SoleProtocolCfg(), MATERIAL_PRESETS[mat], name, ext, cfg)
                response = resupport_response(run.depth, run.force, run.phase, SoleProtocolCfg().weight)
                out.setdefault(mat, {}).setdefault(name, {})[label] = response
    return out


def _probes(paths: list[str], models: dict[str, tuple[RftExtensionsCfg, str]], cfg: SandFitCfg, out: Path) -> dict:
    """Summarise every probe record of the datasets against each model's own run; draw ``fig_resupport.png``."""
    rows: dict[str, dict[str, Any]] = {}
    for path in paths:
        ds = load_dataset(path)
        for name in (n for n in ds.records if n in PROBE_EXPERIMENTS):
            rec = ds.records[name]
            row = {"dataset": path, ds.source: resupport_response(rec.depth, rec.force, rec.phase, ds.protocol.weight)}
            for label, (ext, _) in models.items():
                run = _model_probe(ds.protocol, dataset_material(ds), name, ext, cfg)
                row[label] = resupport_response(run.depth, run.force, run.phase, ds.protocol.weight)
            rows.setdefault(ds.material, {})[name] = row
    if rows:
        _fig_resupport(rows, out / "fig_resupport.png")
    return rows


def _save(fig: Any, path: Path, plt: Any) -> None:
    """Write the figure through a temporary file and close it (a reader never sees half a PNG)."""
    tmp = path.with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=100)
    plt.close(fig)
    tmp.replace(path)


def _fig_resupport(rows: dict[str, dict[str, Any]], path: Path) -> None:
    """Bars of the extra depth [cm] a re-press needed, per material and probe, for the sand and each model.

    Hatched: the first press never carried the single-stance load (``loaded`` false), so the bar is the depth the
    probe reached, not a re-press it needed.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    cells = [(m, n) for m, probes in rows.items() for n in probes]
    labels = [k for k in rows[cells[0][0]][cells[0][1]] if k != "dataset"]
    fig, ax = plt.subplots(figsize=(1.6 + 1.6 * len(cells), 3.4))
    width = 0.8 / len(labels)
    colors = ["k" if i == 0 else f"C{i}" for i in range(len(labels))]
    for i, label in enumerate(labels):
        xs = [c + (i - (len(labels) - 1) / 2) * width for c in range(len(cells))]
        runs = [rows[m][n][label] for m, n in cells]
        bars = ax.bar(xs, [100 * r["extra_depth_m"] for r in runs], width, label=label, color=colors[i])
        for bar, run in zip(bars, runs, strict=True):
            if not run["loaded"]:
                bar.set_hatch("//")
                bar.set_edgecolor("w")
    ax.set_xticks(range(len(cells)), [f"{m}\n{n}" for m, n in cells], fontsize=8)
    ax.set_ylabel("extra depth to carry the load again [cm]")
    ax.grid(axis="y", alpha=0.3)
    ax.legend([Patch(color=c) for c in colors], labels, fontsize=7)  # plain patches: a hatched first bar is no key
    ax.set_title(
        "A loaded sole slid 5 cm or turned 15 deg, then pressed again (hatched: the first press never carried "
        "the load)",
        fontsize=10,
    )
    fig.tight_layout()
    _save(fig, path, plt)


def _replay(ds: CalibrationDataset, ext: RftExtensionsCfg, cfg: SandFitCfg) -> tuple[dict[str, np.ndarray], float]:
    """Return a model's wrenches along the twist (and drag, if recorded) records and its fitted datum [m]."""
    datum = fit_datum(ds, ext, cfg)
    names = [RECORD] + ([DRAG] if DRAG in ds.records else [])
    return replay_wrenches(ds, ext, cfg, names, datum), datum


def _figure(
    series: dict[str, dict[str, dict[str, np.ndarray]]],
    path: Path,
    rows: tuple[tuple[str, str], ...] = (("force_z", "F_z [N]"), ("torque_z", "tau_z about the sole centre [N m]")),
    spans: tuple[int, ...] = TURN_PHASES,
    title: str = "A loaded G1 sole turned about the vertical: MPM against 3D-RFT models",
    shaded: str = "turns +, -, +",
) -> None:
    """Draw each of ``rows`` (series key, axis label) over time per material (columns) for the sand and each model."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mats = list(series)
    fig, axes = plt.subplots(len(rows), len(mats), figsize=(4.2 * len(mats), 2.8 * len(rows)), squeeze=False,
                             sharex="col")  # fmt: skip
    for j, mat in enumerate(mats):
        for i, (label, s) in enumerate(series[mat].items()):
            wide = 2.5 if i == 0 else 1.2
            kw = {"color": f"C{i}" if i else "k", "lw": wide, "alpha": 0.6 if i == 0 else 1.0, "label": label}
            for r, (key, _) in enumerate(rows):
                axes[r, j].plot(s["time"], s[key], **kw)
        first = series[mat][next(iter(series[mat]))]
        for ax in axes[:, j]:
            for k in spans:
                t = first["time"][first["phase"] == k]
                ax.axvspan(t[0], t[-1], color="0.9" if k % 2 else "0.8", zorder=0)
            ax.grid(alpha=0.3)
        for r, (_, label) in enumerate(rows):
            axes[r, j].set(ylabel=label)
        axes[0, j].set(title=mat)
        axes[-1, j].set(xlabel=f"time [s] (shaded: {shaded})")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    _save(fig, path, plt)


def _series(rec: Any, force: np.ndarray, torque_z: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Time series of one sand along a record, for the figures."""
    out = {"time": rec.time, "phase": rec.phase, "force_z": force[:, 2], "force_xy": np.hypot(force[:, 0], force[:, 1])}
    return out if torque_z is None else {**out, "torque_z": torque_z}


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    """Parse the command line."""
    p = argparse.ArgumentParser(
        prog="python -m gmloco.eval.calibration.shear", description=(__doc__ or "").splitlines()[0]
    )
    p.add_argument("--dataset", action="append", default=[], help="<material>.npz with a twist record")
    p.add_argument("--probes", action="append", default=[], help="<material>.npz of probe experiments (re-press)")
    p.add_argument("--predict", action="append", default=[], metavar="MATERIAL",
                   help="each model's probe responses on this material with no MPM record (a prediction)")  # fmt: skip
    p.add_argument("--model", action="append", default=[], metavar="LABEL=PATH",
                   help="fitted extension terms (an extensions file or a fit report); the published 3D-RFT is always "
                   "included")  # fmt: skip
    p.add_argument("--out", required=True, help="folder of summary.json and fig_twist.png")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Measure every dataset's twist against every model; exit 2 on bad input."""
    a = parse_args(argv)
    cfg = SandFitCfg()
    try:
        models: dict[str, tuple[RftExtensionsCfg, str]] = {"published 3D-RFT": (RftExtensionsCfg(), "")}
        for spec in a.model:
            label, sep, path = spec.partition("=")
            if not sep or not label:
                raise ValueError(f"--model expects LABEL=PATH, got {spec!r}")
            models[label] = (load_rft_extensions(path), path)
            held_terms(models[label][0])
        if not a.dataset and not a.probes and not a.predict:
            raise ValueError("give --dataset (a twist record), --probes (probe records) or --predict MATERIAL")
        unknown = sorted(set(a.predict) - set(MATERIAL_PRESETS))
        if unknown:
            raise ValueError(f"--predict {unknown}: unknown material; choose from {sorted(MATERIAL_PRESETS)}")
        for path in a.probes:
            if not any(n in PROBE_EXPERIMENTS for n in load_dataset(path).records):
                raise ValueError(f"{path}: no probe record; record one with python -m gmloco.eval.calibration "
                                 f"--experiments {' '.join(PROBE_EXPERIMENTS)}")  # fmt: skip
        datasets = {}
        for path in a.dataset:
            ds = load_dataset(path)
            if RECORD not in ds.records or not ds.records[RECORD].has_torque:
                raise ValueError(f"{path}: no twist record with a torque; rebuild it with python -m "
                                 "gmloco.eval.calibration --experiments twist")  # fmt: skip
            datasets[path] = ds
    except (OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    summary: dict[str, Any] = {"models": {k: {"path": p, "extensions": asdict(e)} for k, (e, p) in models.items()},
                               "materials": {}}  # fmt: skip
    series: dict[str, dict[str, dict[str, np.ndarray]]] = {}
    drags: dict[str, dict[str, dict[str, np.ndarray]]] = {}
    for path, ds in datasets.items():
        rec, drag = ds.records[RECORD], ds.records.get(DRAG)
        row = {"dataset": path, "source": ds.source, "split": ds.split[RECORD],
               ds.source: twist_response(rec.force, rec.torque[:, 2], rec.phase)}  # fmt: skip
        series[ds.material] = {ds.source: _series(rec, rec.force, rec.torque[:, 2])}
        drag_row: dict[str, Any] = {}
        if drag is not None:
            drag_row[ds.source] = drag_response(drag.force, drag.phase)
            drags[ds.material] = {ds.source: _series(drag, drag.force)}
        for label, (ext, _) in models.items():
            wrenches, datum = _replay(ds, ext, cfg)
            w = wrenches[RECORD]
            row[label] = {"datum_m": datum, **twist_response(w[:, :3], w[:, 5], rec.phase)}
            series[ds.material][label] = _series(rec, w[:, :3], w[:, 5])
            if drag is not None:
                drag_row[label] = drag_response(wrenches[DRAG][:, :3], drag.phase)
                drags[ds.material][label] = _series(drag, wrenches[DRAG][:, :3])
            print(f"{ds.material}: {label} replayed at datum {100 * datum:.2f} cm", flush=True)
        summary["materials"][ds.material] = {**row, "drag": drag_row or None}
    summary["probes"] = _probes(a.probes, models, cfg, out) or None
    summary["probe_predictions"] = predict_probes(a.predict, models, cfg) or None
    atomic_write_json(out / "summary.json", summary)
    if series:
        _figure(series, out / "fig_twist.png")
    if drags:
        _figure(drags, out / "fig_drag.png", rows=(("force_z", "F_z [N]"), ("force_xy", "|F_xy| [N]")),
                spans=(DRAG_PHASES[1],), title="A loaded G1 sole slid 10 cm sideways at constant depth, then at rest",
                shaded="the slide")  # fmt: skip
    print(f"{out}/summary.json: {len(datasets)} twist datasets, {len(a.probes)} probe datasets, {len(models)} models")
    return 0


if __name__ == "__main__":
    sys.exit(main())
