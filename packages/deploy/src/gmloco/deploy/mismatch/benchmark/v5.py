# SPDX-License-Identifier: Apache-2.0
"""Benchmark v5: three suites (plane stepping, sand composite walking, fixed-base chirp), pre-registered.

The protocol is ``results/mismatch_benchmark/v5/protocol.md``; this module is its runner. Usage::

    python -m gmloco.deploy.mismatch.benchmark.v5 --out results/mismatch_benchmark/v5 --suite fixed
        [--workers N] [--part I/N] [--resume] [--deadline-s S] [--list] [--score-only]

Every suite has two seeds per library class at mid strength, two per out-of-library class and
``NULLS_PER_SUITE`` nulls. The seeds are fixed here (``SEED_BASE``) and fresh: no earlier benchmark, floor
calibration or tuning run used them. Rows go to ``OUT/<suite>/rows``; ``OUT/<suite>/summary.json`` scores one
suite and ``OUT/summary_pooled.json`` pools every class of every suite scored so far.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from dataclasses import replace
from multiprocessing import Pool
from pathlib import Path

import numpy as np

from gmloco.deploy.config_cli import Flag, add_flags, cfg_from_flags, check_flags, field_doc
from gmloco.deploy.mismatch.benchmark.episodes import MID, OOL, SAND_MID_V4, SAND_OOL
from gmloco.deploy.mismatch.benchmark.sweep import _part_spec
from gmloco.deploy.mismatch.benchmark.v5_cfg import V5RunCfg

__all__ = ["FIXED_MID_V5", "FLAGS", "NEW_MID_V5", "NULLS_PER_SUITE", "SEED_BASE", "SUITES", "TARGETS", "suite_episodes"]

_LEG = 12
_KNEE_L, _HIP_PITCH_R, _ANKLE_PITCH_R = 3, 6, 10  # leg-joint indices (G1_JOINT_NAMES order)


def _leg(values: dict[int, float]) -> list[float]:
    """A 12-vector over the leg joints, zero except at the given indices."""
    out = [0.0] * _LEG
    for i, v in values.items():
        out[i] = v
    return out


NEW_MID_V5: dict[str, dict[str, list[float]]] = {
    "actuator.torque_limit": {"limit_loss": [0.4]},
    "actuator.backlash": {"width": [0.0, 0.02, 0.0]},
    "body.limb_mass": {"delta_mass": [0.0, 0.0, 1.0, 0.0]},
    "joint.coulomb_friction_leg": {"tau_c": _leg({_KNEE_L: 2.0, _ANKLE_PITCH_R: 1.0})},
    "joint.viscous_damping_leg": {"b": _leg({_KNEE_L: 1.0, _HIP_PITCH_R: 0.6})},
}
"""Mid strengths of the classes v5 adds (every component that is set is >= 1.5x its tolerance, v4's rule):
a 40 % lower peak torque, 0.02 rad knee backlash, +1 kg on the left shank, left-knee / right-ankle-pitch dry
friction 2 / 1 N*m, left-knee / right-hip-pitch damping 1 / 0.6 N*m*s/rad."""

FIXED_MID_V5: dict[str, dict[str, list[float]]] = {
    **{k: v for k, v in MID.items() if not k.startswith("terrain.")},
    **NEW_MID_V5,
}
"""Fixed-base chirp suite: every library class that can act on a held robot (no terrain class)."""

SUITES: dict[str, dict] = {
    "plane": {
        "mid": {**MID, **NEW_MID_V5},
        "ool": OOL,
        "episode": {"duration": 9.0},
    },
    "sand": {
        "mid": {**SAND_MID_V4, **NEW_MID_V5},
        "ool": SAND_OOL,
        "episode": {
            "duration": 18.0,
            "ground": "sand",
            "material": "dry_sand",
            "policy": True,
            "odometry": True,
            "motion": "composite",
        },
    },
    "fixed": {
        "mid": FIXED_MID_V5,
        "ool": OOL,
        "episode": {"duration": 9.0, "support": "gantry", "chirp": True},
    },
}
"""Per suite: mid-strength table, out-of-library classes, and the episode fields every episode carries."""

SEED_BASE: dict[str, int] = {"plane": 51000, "sand": 52000, "fixed": 53000}
"""First seed of each suite; classes take ``base + 10 i + s``, out-of-library ``base + 500 + 10 j + s``, nulls
``base + 900 + n``. Fresh: every earlier benchmark and calibration seed is below 30000."""

SEEDS_PER_CLASS = 2
"""Seeds per library and out-of-library class."""
NULLS_PER_SUITE = 20
"""Null episodes per suite (the false-positive rate's denominator)."""

TARGETS: dict[str, float] = {
    "top1_pooled": 0.8,
    "false_positive_max": 0.05,
    "ool_unexplained": 0.8,
}
"""Pre-registered targets; interval coverage is reported without a target."""


def suite_episodes(suite: str) -> list[dict]:
    """Episode dicts of one suite, in a fixed order (``sweep.run_episode`` input)."""
    if suite not in SUITES:
        raise ValueError(f"unknown suite {suite!r}; suites: {sorted(SUITES)}")
    cfg, base = SUITES[suite], SEED_BASE[suite]
    eps = []
    for i, (eid, p) in enumerate(cfg["mid"].items()):
        for s in range(SEEDS_PER_CLASS):
            eps.append({"name": f"{suite}-{eid}-{s}", "effect": eid, "params": p, "strength": "mid",
                        "seed": base + 10 * i + s})  # fmt: skip
    for j, (eid, p) in enumerate(cfg["ool"].items()):
        for s in range(SEEDS_PER_CLASS):
            eps.append({"name": f"{suite}-{eid}-{s}", "effect": eid, "params": p, "strength": "mid",
                        "seed": base + 500 + 10 * j + s})  # fmt: skip
    for n in range(NULLS_PER_SUITE):
        eps.append({"name": f"{suite}-none-{n}", "effect": "none", "params": {}, "strength": "none",
                    "seed": base + 900 + n})  # fmt: skip
    return [{**e, **cfg["episode"], "suite": suite} for e in eps]


def pooled(rows_by_suite: dict[str, list[dict]]) -> dict:
    """Pooled scores over every (suite, class): top-1 macro, null false positives, out-of-library, coverage."""
    from gmloco.deploy.mismatch.benchmark.scorer import score

    top1, cover, fp, ool, per_suite = [], [], [], [], {}
    for suite, rows in rows_by_suite.items():
        sc = score(rows)
        per_suite[suite] = sc["overall"]
        for k, v in sc["per_effect"].items():
            if k.endswith("@mid") and not k.startswith("ool.") and v.get("top1") is not None:
                top1.append(v["top1"])
            if v.get("coverage") is not None:
                cover.append(v["coverage"])
        fp += [r["verdict"] != "no_mismatch" for r in rows if r.get("effect") == "none" and "verdict" in r]
        ool += [
            r["verdict"] == "unexplained" for r in rows if r.get("effect", "").startswith("ool.") and "verdict" in r
        ]
    out = {
        "classes": len(top1),
        "top1_pooled": float(np.mean(top1)) if top1 else None,
        "null_episodes": len(fp),
        "false_positive_rate": float(np.mean(fp)) if fp else None,
        "ool_episodes": len(ool),
        "ool_unexplained": float(np.mean(ool)) if ool else None,
        "ci_coverage": float(np.mean(cover)) if cover else None,
        "targets": TARGETS,
    }
    out["met"] = {
        "top1_pooled": out["top1_pooled"] is not None and out["top1_pooled"] >= TARGETS["top1_pooled"],
        "false_positive": out["false_positive_rate"] is not None
        and out["false_positive_rate"] <= TARGETS["false_positive_max"],
        "ool_unexplained": out["ool_unexplained"] is not None and out["ool_unexplained"] >= TARGETS["ool_unexplained"],
    }
    return {"pooled": out, "per_suite": per_suite}


def _rows(d: Path) -> list[dict]:
    """Rows already written under ``d/rows``."""
    return [json.loads(f.read_text()) for f in sorted((d / "rows").glob("*.json"))]


def _write_json(path: Path, obj: dict) -> None:
    """Write JSON atomically (temporary file, then rename)."""
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(json.dumps(obj, indent=2, default=float))
    tmp.replace(path)


def _run_all(args: list[tuple], workers: int, suite: str) -> list[dict]:
    """Run the episodes in ``workers`` processes, in order, with a progress bar on stderr; return their rows."""
    from rich.console import Console
    from rich.progress import Progress, TimeElapsedColumn

    from gmloco.deploy.mismatch.benchmark.sweep import _star

    done = []
    columns = (*Progress.get_default_columns(), TimeElapsedColumn())
    with Pool(workers) as pool, Progress(*columns, console=Console(stderr=True)) as prog:
        task = prog.add_task(f"{suite}: {len(args)} episodes", total=len(args))
        for row in pool.imap(_star, args, chunksize=1):
            done.append(row)
            outcome = row.get("verdict") or ("error" if "error" in row else "skipped")
            prog.update(task, advance=1, description=f"{suite}: {row['name']} {outcome}")
    return done


FLAGS: tuple[Flag, ...] = (
    Flag("--workers", "workers"),
    Flag("--part", "part", parse=_part_spec),
    Flag("--only", "only", sep=","),
    Flag("--resume", "resume"),
    Flag("--deadline-s", "deadline_s"),
    Flag("--list", "list_episodes"),
    Flag("--score-only", "score_only"),
)
"""The flags generated from :class:`V5RunCfg` (``--out`` and the required ``--suite`` are the command line's own)."""


def _parse(argv: list[str] | None) -> tuple[Path, V5RunCfg]:
    """The results folder and run config of the arguments (exit code 2 on a malformed or out-of-range one)."""
    p = argparse.ArgumentParser(prog="mismatch-benchmark-v5", description=__doc__)
    p.add_argument("--out", type=Path, required=True, help="v5 results directory (suites go to OUT/<suite>)")
    p.add_argument("--suite", choices=sorted(SUITES), required=True, help=field_doc(V5RunCfg, "suite"))
    add_flags(p, V5RunCfg(), FLAGS)
    a = p.parse_args(argv)
    check_flags(p, a, V5RunCfg, FLAGS)
    return a.out, replace(cfg_from_flags(a, V5RunCfg(), FLAGS), suite=a.suite)


def main(argv: list[str] | None = None) -> int:
    """Run (part of) one suite, then score it and the pool; exit 2 on bad arguments."""
    from gmloco.deploy.mismatch.benchmark.sweep import _git_commit, _part

    root, cfg = _parse(argv)
    eps = suite_episodes(cfg.suite)
    if cfg.list_episodes:
        for e in eps:
            print(e["name"], e["seed"])
        return 0
    eps = _part(eps, cfg.part)
    if cfg.only:
        eps = [e for e in eps if any(e["name"].startswith(s) for s in cfg.only)]
    out = root / cfg.suite
    if not cfg.score_only:
        out.mkdir(parents=True, exist_ok=True)
        todo = [e for e in eps if not (cfg.resume and (out / "rows" / f"{e['name']}.json").exists())]
        t0 = time.time()
        deadline = None if cfg.deadline_s is None else t0 + cfg.deadline_s
        args = [(e, str(out), e["duration"], None, None, deadline) for e in todo]
        done = _run_all(args, cfg.workers, cfg.suite)
        run = {"suite": cfg.suite, "argv": argv if argv is not None else sys.argv[1:], "ran": [r["name"] for r in done
               if "skipped" not in r], "wall_s": time.time() - t0, "cpus": os.cpu_count(), "git": _git_commit()}  # fmt: skip
        (out / "runs").mkdir(exist_ok=True)
        _write_json(out / "runs" / f"{time.strftime('%Y%m%dT%H%M%S')}.json", run)
        print(json.dumps({k: v for k, v in run.items() if k != "ran"} | {"ran": len(run["ran"])}))
    from gmloco.deploy.mismatch.benchmark.scorer import score

    rows = _rows(out)
    _write_json(out / "summary.json", {**score(rows), "episodes_scored": len(rows)})
    by_suite = {s: _rows(root / s) for s in SUITES if (root / s / "rows").is_dir()}
    _write_json(root / "summary_pooled.json", pooled(by_suite))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
