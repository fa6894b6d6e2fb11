# SPDX-License-Identifier: Apache-2.0
"""MPM success against the training simulator's prediction, per policy, material and speed; bad input exits 2.

The prediction of a contact model is the gate's straight-walking success (``python -m gmloco.train.gate
--contact-model NAME --parts success``), by MPM's rule by default (``success_course_pct``: survived *and* walked
the course; ``--criterion survival`` compares survival alone, ``success_pct``); the judge is the committed MPM
success by speed (``speed_rows`` of ``results/mpm_eval/summary.json`` or ``tables/tables.json``, or
``tables/table_speeds.csv``).

python -m gmloco.eval.calibration.predict --gate results/sand_calibration/gate_*.json
        --mpm results/mpm_eval/summary.json --out results/sand_calibration/predicted_vs_mpm_success.json
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from gmloco.deploy.atomic_io import atomic_write_json
from gmloco.eval.calibration.dataset import read_json_object

__all__ = ["MAX_POINTS", "PredictCfg", "predict_success", "read_gate", "read_mpm_speeds"]

MAX_POINTS = 15.0
"""A prediction is right when |predicted - MPM success| is at most this [percentage points] (issue 35's test)."""

_SPEED_COLUMN = re.compile(r"^v=([0-9.]+) m/s$")
"""Column of the MPM speed table holding the success [%] at one commanded speed, e.g. ``v=1.5 m/s``."""


Criterion = Literal["course", "survival"]
"""Which gate success predicts MPM's: ``course`` (MPM's rule) or ``survival`` (no fall, the course ignored)."""

_GATE_KEY: dict[str, str] = {"course": "success_course_pct", "survival": "success_pct"}
"""Gate summary key of each criterion."""

_CRITERION_NOTE: dict[str, str] = {
    "course": "MPM's rule: survived and walked 1 - course_slack of the commanded line (success_course_pct)",
    "survival": "survival alone, the course ignored (success_pct)",
}
"""What the predicted success counts, per criterion (the JSON's notes)."""


@dataclass(frozen=True)
class PredictCfg:
    """What is compared and the tolerance of a prediction."""

    criterion: Criterion = "course"
    """Gate success compared with MPM's: ``course`` counts a survivor that did not walk ``1 - course_slack`` of
    its commanded line as failed, as MPM does; ``survival`` counts falls only."""

    scenario: str = "straight"
    """MPM scenario whose speed rows are compared (the gate's forward cells walk straight)."""
    figures: bool = True
    """Write one figure per policy beside the JSON."""
    walks: bool = True
    """Beside each cell, how the walks differ (``mpm_walk``, ``gate_walk``: falls, unfinished courses, velocity
    error, heading change; :mod:`gmloco.eval.calibration.walk_gap`) when the MPM summary names the policy's run
    folders (``runs.<policy>.dirs``)."""
    only_judged_materials: bool = False
    """Compare a policy on the materials MPM has judged it on and list the others under ``not_judged_on_mpm``
    (False: a gated material without an MPM row is an error)."""


def _speed_key(v: float) -> str:
    """Speed [m/s] as a JSON key, the gate's form: ``1``, ``1.5``."""
    return f"{v:g}"


def read_gate(path: str | Path, criterion: Criterion = "course") -> tuple[str, str, dict[str, dict[str, float]]]:
    """Return (policy name, contact model, success [%] by material and speed key) of a gate summary."""
    body = read_json_object(path, "gate summary")
    success, setup = body.get(_GATE_KEY[criterion]), body.get("setup", {})
    if "policy" not in body or not isinstance(setup, dict) or "contact_model" not in setup:
        raise ValueError(
            f"gate summary {path} lacks policy or setup.contact_model: is it python -m gmloco.train.gate's?"
        )
    if criterion == "course" and isinstance(body.get("success_pct"), dict) and success is None:
        raise ValueError(
            f"gate summary {path} has no success_course_pct (MPM's course rule): rerun the gate with this code, or "
            "compare survival alone with --criterion survival"
        )
    if not isinstance(success, dict) or not success:
        raise ValueError(f"gate summary {path} has no success table: run the gate with --parts success")
    table = {m: {_speed_key(float(v)): float(s) for v, s in row.items() if s is not None} for m, row in success.items()}
    return Path(str(body["policy"]).rstrip("/")).name, str(setup["contact_model"]), table


def _speed_rows(path: Path) -> list[dict[str, Any]]:
    """Rows (policy, terrain, scenario, ``v=<speed> m/s`` columns) of an MPM speed table, JSON or CSV."""
    if path.suffix == ".csv":
        if not path.is_file():
            raise FileNotFoundError(f"MPM speed table {path} not found")
        with path.open(newline="") as fh:
            return list(csv.DictReader(fh))
    rows = read_json_object(path, "MPM summary").get("speed_rows")
    if not isinstance(rows, list):
        raise ValueError(f"MPM summary {path} has no speed_rows: give results/mpm_eval/summary.json")
    return rows


def read_mpm_speeds(path: str | Path, scenario: str = "straight") -> dict[str, dict[str, dict[str, float]]]:
    """Return MPM success [%] by policy, terrain and speed key of the ``scenario`` rows of an MPM speed table."""
    out: dict[str, dict[str, dict[str, float]]] = {}
    for row in _speed_rows(Path(path)):
        if row.get("scenario") != scenario:
            continue
        speeds = {}
        for column, value in row.items():
            match = _SPEED_COLUMN.match(str(column))
            if match and value not in (None, ""):
                speeds[_speed_key(float(match.group(1)))] = float(value)
        out.setdefault(str(row["policy"]), {})[str(row["terrain"])] = speeds
    if not out:
        raise ValueError(f"MPM speed table {path} has no {scenario!r} rows")
    return out


def _gates(paths: list[str], criterion: Criterion) -> tuple[dict[str, Any], dict[str, dict[str, dict[str, str]]]]:
    """Return success [%] by policy, contact model, material and speed key, and the file of each of those materials.

    Gates of one policy and contact model that cover different materials are merged (a sand with terms fitted per
    material gates each material on its own terms); two that share a material are refused.
    """
    out: dict[str, dict[str, dict[str, dict[str, float]]]] = {}
    files: dict[str, dict[str, dict[str, str]]] = {}
    for path in paths:
        policy, model, table = read_gate(path, criterion)
        have = out.setdefault(policy, {}).setdefault(model, {})
        shared = sorted(set(have) & set(table))
        if shared:
            raise ValueError(
                f"two gate summaries of {policy} with contact model {model!r} both cover {shared}: give one gate per "
                f"material ({path})"
            )
        have.update(table)
        files.setdefault(policy, {}).setdefault(model, {}).update(dict.fromkeys(table, str(path)))
    return out, files


def _mpm_dirs(path: Path) -> dict[str, list[str]]:
    """Run folders of each policy in an MPM summary (``runs.<policy>.dirs``); {} for a CSV table or none."""
    if path.suffix == ".csv":
        return {}
    runs = read_json_object(path, "MPM summary").get("runs")
    if not isinstance(runs, dict):
        return {}
    return {p: list(r["dirs"]) for p, r in runs.items() if isinstance(r, dict) and isinstance(r.get("dirs"), list)}


def _add_walks(table: dict[str, Any], files: dict[str, dict[str, str]], dirs: list[str], scenario: str) -> None:
    """Put ``mpm_walk`` and ``gate_walk`` (per model) beside every cell of one policy's table."""
    from gmloco.eval.calibration.walk_gap import gate_walk, mpm_walks

    walks = mpm_walks(dirs, scenario)
    paths = {path for by_material in files.values() for path in by_material.values()}
    bodies = {path: read_json_object(path, "gate summary") for path in sorted(paths)}
    for material, cells in table.items():
        for speed, cell in cells.items():
            cell["mpm_walk"] = walks.get(material, {}).get(speed)
            cell["gate_walk"] = {
                model: gate_walk(bodies[by_material[material]], material, speed) if material in by_material else None
                for model, by_material in files.items()
            }


def _cell(mpm: float, predicted: dict[str, float | None], cfg: PredictCfg) -> dict[str, Any]:
    """One (policy, material, speed): MPM success, each model's, their difference [points] and its verdict."""
    diff = {m: None if p is None else p - mpm for m, p in predicted.items()}
    return {
        "mpm_success_pct": mpm,
        "predicted_success_pct": predicted,
        "difference_points": diff,
        "within_15_points": {m: None if d is None else bool(abs(d) <= MAX_POINTS) for m, d in diff.items()},
    }


def _compare(policy: str, gates: dict[str, Any], mpm: dict[str, dict[str, float]], cfg: PredictCfg) -> dict:
    """Cells of one policy: every material of its gates, every speed both the gates and MPM have."""
    materials = sorted({m for table in gates.values() for m in table})
    unknown = [m for m in materials if m not in mpm]
    if unknown and cfg.only_judged_materials:
        materials = [m for m in materials if m in mpm]
    elif unknown:
        raise ValueError(
            f"{policy}: materials {unknown} of the gate have no MPM {cfg.scenario} row; MPM has {sorted(mpm)}"
        )
    out: dict[str, Any] = {}
    for material in materials:
        speeds = [v for v in mpm[material] if any(v in t.get(material, {}) for t in gates.values())]
        if not speeds:
            raise ValueError(f"{policy} on {material}: no speed in both the gate and MPM (MPM: {list(mpm[material])})")
        out[material] = {v: _cell(mpm[material][v], {m: t.get(material, {}).get(v) for m, t in gates.items()}, cfg)
                         for v in sorted(speeds, key=float)}  # fmt: skip
    return out


def _all_within(table: dict[str, Any], model: str) -> bool | None:
    """Every cell of a model within the tolerance (None if the model predicts none)."""
    flags = [c["within_15_points"].get(model) for per in table.values() for c in per.values()]
    flags = [f for f in flags if f is not None]
    return all(flags) if flags else None


def predict_success(gates: list[str], mpm: str, out: str | Path, cfg: PredictCfg) -> dict[str, Any]:
    """Compare gate summaries with the MPM success by speed; write the JSON (and figures) to ``out``; return it.

    Raises:
        ValueError: If a gate's policy or material has no MPM speed row, or no speed is in both.
    """
    judged, (predicted, files) = read_mpm_speeds(mpm, cfg.scenario), _gates(gates, cfg.criterion)
    runs = _mpm_dirs(Path(mpm)) if cfg.walks else {}
    table: dict[str, Any] = {}
    not_judged: dict[str, list[str]] = {}
    for policy, by_model in predicted.items():
        if policy not in judged:
            raise ValueError(
                f"policy {policy!r} has no MPM {cfg.scenario} speed rows in {mpm}; MPM has {sorted(judged)}"
            )
        table[policy] = _compare(policy, by_model, judged[policy], cfg)
        if policy in runs:
            _add_walks(table[policy], files[policy], runs[policy], cfg.scenario)
        gated = {m for t in by_model.values() for m in t}
        if gated - set(table[policy]):
            not_judged[policy] = sorted(gated - set(table[policy]))
    models = sorted({m for by_model in predicted.values() for m in by_model})
    body: dict[str, Any] = {
        "predicted_vs_mpm_success": table,
        "within_15_points": {p: {m: _all_within(t, m) for m in models} for p, t in table.items()},
        "contact_models": models,
        "max_points": MAX_POINTS,
        "scenario": cfg.scenario,
        "criterion": cfg.criterion,
        "notes": {
            "predicted_success_pct": "straight-walking success [%] of the gate in the training simulator, per model; "
            + _CRITERION_NOTE[cfg.criterion],
            "difference_points": "predicted - MPM success [percentage points]; only speeds MPM has are compared",
            "mpm_walk": "the policy's MPM episodes of the cell: fell / course unfinished / success [%], median "
            "velocity error [m/s] and largest heading turn from the start [deg]",
            "gate_walk": "the gate's episodes of the cell, per model: fell / course unfinished [%], mean velocity "
            "error [m/s], survivors' heading drift at the end [deg]",
        },
        "not_judged_on_mpm": not_judged,
        "inputs": {"gates": list(gates), "mpm": str(mpm)},
        "figures": [],
    }
    out = Path(out)
    if cfg.figures:
        out.parent.mkdir(parents=True, exist_ok=True)
        from gmloco.eval.calibration.figures import fig_predicted_success

        body["figures"] = [str(fig_predicted_success(policy, t, out.parent / f"predicted_success_{policy}.png"))
                           for policy, t in table.items()]  # fmt: skip
    atomic_write_json(out, body, allow_nan=False, newline=True)
    return body


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    """Parse the command line."""
    p = argparse.ArgumentParser(
        prog="python -m gmloco.eval.calibration.predict", description=(__doc__ or "").splitlines()[0]
    )
    p.add_argument("--gate", nargs="+", required=True, help="gate summaries (python -m gmloco.train.gate)")
    p.add_argument("--mpm", default="results/mpm_eval/summary.json", help="MPM summary or table_speeds.csv")
    p.add_argument("--out", default="results/sand_calibration/predicted_vs_mpm_success.json")
    p.add_argument("--criterion", choices=list(_GATE_KEY), default="course",
                   help="gate success compared: MPM's rule (course, default) or survival alone")  # fmt: skip
    p.add_argument("--no-figures", action="store_true")
    p.add_argument("--no-walks", action="store_true", help="leave out the per-cell walk comparison")
    p.add_argument("--only-judged-materials", action="store_true",
                   help="compare each policy on the materials MPM judged it on; list the others (default: error)")  # fmt: skip
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Compare and write; return the exit code (2: bad input)."""
    a = parse_args(argv)
    try:
        body = predict_success(
            a.gate,
            a.mpm,
            a.out,
            PredictCfg(
                criterion=a.criterion,
                figures=not a.no_figures,
                walks=not a.no_walks,
                only_judged_materials=a.only_judged_materials,
            ),
        )
    except (FileNotFoundError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(json.dumps({"within_15_points": body["within_15_points"], "out": a.out}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
