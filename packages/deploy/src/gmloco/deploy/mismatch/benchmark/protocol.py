# SPDX-License-Identifier: Apache-2.0
"""The runner of a pre-registered benchmark (v5, v6): its suites, fresh seeds, targets, rows and pooled scores.

A :class:`Protocol` is data (which classes each suite runs at which strength, the seeds, the targets); each
version's module (:mod:`.v5`, :mod:`.v6`) holds one and hands its command line to :func:`main`. Rows go to
``OUT/<suite>/rows``; ``OUT/<suite>/summary.json`` scores one suite and ``OUT/summary_pooled.json`` pools every
class of every suite scored so far, with the suites a protocol carries over from an earlier version's folder.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from dataclasses import dataclass, field, replace
from multiprocessing import Pool
from pathlib import Path

import numpy as np

from gmloco.deploy.config_cli import Flag, add_flags, cfg_from_flags, check_flags, field_doc
from gmloco.deploy.mismatch.benchmark.protocol_cfg import ProtocolRunCfg
from gmloco.deploy.mismatch.benchmark.sweep import _part_spec

__all__ = ["FLAGS", "SEEDS_PER_CLASS", "TARGETS", "Protocol", "main", "parse", "pooled", "suite_episodes"]

SEEDS_PER_CLASS = 2
"""Seeds per library and out-of-library class."""

TARGETS: dict[str, float] = {
    "top1_pooled": 0.8,
    "false_positive_max": 0.05,
    "ool_unexplained": 0.8,
}
"""Pre-registered targets (issue 41's); interval coverage is reported without a target."""


@dataclass(frozen=True)
class Protocol:
    """One benchmark version: suites, seeds, nulls, and the suites carried over from an earlier version."""

    name: str
    """Version, e.g. ``v6`` (the command's name and the results folder's)."""
    suites: dict[str, dict]
    """Per suite: ``mid`` (class -> truth parameters), ``ool`` (out-of-library classes) and ``episode`` (the
    fields every episode carries; ``stages`` makes one robot's recordings one diagnosis)."""
    seed_base: dict[str, int]
    """First seed of each suite: classes take ``base + 10 i + s``, out-of-library ``base + 500 + 10 j + s``, nulls
    ``base + 900 + n``."""
    nulls_per_suite: int = 20
    """Null episodes per suite (the false-positive rate's denominator)."""
    carried: dict[str, str] = field(default_factory=dict)
    """Suites pooled from an earlier version as scored there: suite -> its folder, relative to ``OUT/..``."""


def suite_episodes(protocol: Protocol, suite: str) -> list[dict]:
    """Episode dicts of one suite, in a fixed order (``sweep.run_episode`` input)."""
    if suite not in protocol.suites:
        raise ValueError(f"unknown suite {suite!r}; suites: {sorted(protocol.suites)}")
    cfg, base = protocol.suites[suite], protocol.seed_base[suite]
    eps = []
    for i, (eid, p) in enumerate(cfg["mid"].items()):
        for s in range(SEEDS_PER_CLASS):
            eps.append({"name": f"{suite}-{eid}-{s}", "effect": eid, "params": p, "strength": "mid",
                        "seed": base + 10 * i + s})  # fmt: skip
    for j, (eid, p) in enumerate(cfg["ool"].items()):
        for s in range(SEEDS_PER_CLASS):
            eps.append({"name": f"{suite}-{eid}-{s}", "effect": eid, "params": p, "strength": "mid",
                        "seed": base + 500 + 10 * j + s})  # fmt: skip
    for n in range(protocol.nulls_per_suite):
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
"""The flags generated from :class:`ProtocolRunCfg` (``--out`` and the required ``--suite`` are the command line's own)."""


def parse(protocol: Protocol, argv: list[str] | None, doc: str | None = None) -> tuple[Path, ProtocolRunCfg]:
    """The results folder and run config of the arguments (exit code 2 on a malformed or out-of-range one)."""
    p = argparse.ArgumentParser(prog=f"mismatch-benchmark-{protocol.name}", description=doc or __doc__)
    p.add_argument("--out", type=Path, required=True,
                   help=f"{protocol.name} results directory (suites go to OUT/<suite>)")  # fmt: skip
    p.add_argument("--suite", choices=sorted(protocol.suites), required=True, help=field_doc(ProtocolRunCfg, "suite"))
    add_flags(p, ProtocolRunCfg(), FLAGS)
    a = p.parse_args(argv)
    check_flags(p, a, ProtocolRunCfg, FLAGS)
    return a.out, replace(cfg_from_flags(a, ProtocolRunCfg(), FLAGS), suite=a.suite)


def main(protocol: Protocol, argv: list[str] | None = None, doc: str | None = None) -> int:
    """Run (part of) one suite, then score it and the pool; exit 2 on bad arguments."""
    from gmloco.deploy.mismatch.benchmark.sweep import _git_commit, _part, source_sha256

    root, cfg = parse(protocol, argv, doc)
    eps = suite_episodes(protocol, cfg.suite)
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
               if "skipped" not in r], "wall_s": time.time() - t0, "cpus": os.cpu_count(), "git": _git_commit(),
               "source_sha256": source_sha256()}  # fmt: skip
        (out / "runs").mkdir(exist_ok=True)
        _write_json(out / "runs" / f"{time.strftime('%Y%m%dT%H%M%S')}.json", run)
        print(json.dumps({k: v for k, v in run.items() if k != "ran"} | {"ran": len(run["ran"])}))
    from gmloco.deploy.mismatch.benchmark.scorer import score

    rows = _rows(out)
    _write_json(out / "summary.json", {**score(rows), "episodes_scored": len(rows)})
    by_suite = {s: _rows(root / s) for s in protocol.suites if (root / s / "rows").is_dir()}
    carried = {s: root.parent / d for s, d in protocol.carried.items() if (root.parent / d / "rows").is_dir()}
    by_suite |= {s: _rows(d) for s, d in carried.items()}
    summary = pooled(by_suite) | {"carried": {s: str(d) for s, d in carried.items()}}
    _write_json(root / "summary_pooled.json", summary)
    return 0
