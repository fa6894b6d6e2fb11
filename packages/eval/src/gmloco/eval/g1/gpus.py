# SPDX-License-Identifier: Apache-2.0
"""The MPM evaluation of one policy over several GPUs, as one run (the pipeline's ``eval_mpm`` with ``gpus``).

One GPU steps ~110-130 robot-frames/s at the accepted setting, so 100 walking episodes of one cell take ~26-30
minutes on it (``BENCHMARKS.md``). :func:`run_on_gpus` splits each (terrain, scenario) cell of a ``G1EvalCfg`` into
one share per GPU (``--shard I/N``: the episodes whose index k has k % N == I), runs the shares through
:mod:`gmloco.eval.g1.queue` (one ``g1.cli`` process per GPU, the whole queue time-boxed to
``cfg.max_minutes``), and pools them into the outputs a one-process run writes under ``cfg.out_dir``:
``episodes.jsonl`` (pooled; the same episode keys as a one-process run, so either kind resumes the other:
share folders without episodes start from their share of it),
``summary.json``, the tables and figures. The shares' own folders stay under ``cfg.out_dir/cells`` (their
recordings, logs and resume state; rerunning resumes each) beside the queue's ``queue.json``.
"""

from __future__ import annotations

import json
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from gmloco.eval.g1.cli import cli_args
from gmloco.eval.g1.config import G1EvalCfg, episode_specs
from gmloco.eval.g1.queue import Launch, QueueTask, TaskResult, cell_tasks, row_spans, run_queue
from gmloco.eval.g1.run import write_outputs
from gmloco.eval.g1.window_report import report_window
from gmloco.eval.metrics.episodes import read_episodes, summarize

__all__ = ["CELLS_DIR", "run_on_gpus"]

CELLS_DIR = "cells"
"""Folder under the run's ``out_dir`` holding one run folder per (cell, share)."""


def _share_state(folder: Path, result: TaskResult) -> tuple[list[dict[str, Any]], bool, float]:
    """(episodes, finished all its episodes, episodes added by this call) of one share's run folder."""
    rows = read_episodes(folder / "episodes.jsonl") if (folder / "episodes.jsonl").exists() else []
    path = folder / "summary.json"
    if result.gpu is None or result.returncode != 0 or not path.exists():
        return rows, False, 0.0
    doc = json.loads(path.read_text())
    return rows, bool(doc.get("complete")), float(doc.get("metrics", {}).get("throughput/episodes_this_call", 0.0))


def _seed_shares(out: Path, cfg: G1EvalCfg, tasks: list[QueueTask]) -> None:
    """Give each share folder without episodes its share of the run's pooled ``episodes.jsonl``, if there is one.

    So a run resumes whatever wrote that file last: a one-process run, or shares of another GPU count. ``tasks``
    are ``cell_tasks``' for ``cfg``: cell after cell, the shares of a cell in order.
    """
    pooled = out / "episodes.jsonl"
    if not pooled.exists():
        return
    rows = read_episodes(pooled, repair=True)
    n = len(tasks) // (len(cfg.terrains) * len(cfg.scenarios))
    shares = [replace(cfg, terrains=(t,), scenarios=(sc,), shard=i, shards=n)
              for t in cfg.terrains for sc in cfg.scenarios for i in range(n)]  # fmt: skip
    for task, share in zip(tasks, shares, strict=True):
        folder = out / CELLS_DIR / task.name
        if (folder / "episodes.jsonl").exists():
            continue
        keys = {spec.key for spec in episode_specs(share)}
        if mine := [r for r in rows if r["key"] in keys]:
            folder.mkdir(parents=True, exist_ok=True)
            (folder / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in mine))


def run_on_gpus(
    cfg: G1EvalCfg, gpus: list[str], launch: Launch | None = None, poll_s: float = 2.0
) -> tuple[dict[str, float], bool]:
    """Run (or resume) the evaluation ``cfg`` over ``gpus``; return (pooled summary metrics, complete).

    Args:
        cfg: The evaluation (its ``device`` and ``shard`` are set per process; each GPU is the process's ``cuda:0``).
        gpus: ``CUDA_VISIBLE_DEVICES`` values, one process at a time on each.
        launch: Process starter (tests pass a stand-in; default: ``g1.cli`` processes).
        poll_s: How often the queue looks at its processes [s].

    Raises:
        ValueError: No GPU, a GPU named twice, a sharded config, or a setting the command line cannot pass.
        RuntimeError: A share's process failed (after the pooled outputs of the others are written).
    """
    if cfg.shards != 1:
        raise ValueError(f"cfg.shards = {cfg.shards}: run_on_gpus shards the cells itself; pass an unsharded config")
    out = Path(cfg.out_dir)
    cells = out / CELLS_DIR
    tasks = cell_tasks(list(cfg.terrains), list(cfg.scenarios), cli_args(cfg, cells=False), shards=len(gpus))
    if cfg.resume:
        _seed_shares(out, cfg, tasks)
    extra: dict[str, Any] = {} if launch is None else {"launch": launch}
    results = run_queue(tasks, gpus, cells, cfg.max_minutes, poll_s=poll_s, **extra)
    (cells / "queue.json").write_text(json.dumps({"gpus": gpus, "max_minutes": cfg.max_minutes,
                                                  "tasks": [asdict(r) for r in results],
                                                  "rows": row_spans(results)}, indent=1) + "\n")  # fmt: skip
    rows, complete, added = [], True, 0.0
    for task, result in zip(tasks, results, strict=True):
        share_rows, share_done, share_added = _share_state(cells / task.name, result)
        rows += share_rows
        complete &= share_done
        added += share_added
    failed = [r for r in results if r.returncode not in (0, None)]
    rows.sort(key=lambda r: (r["terrain"], r["scenario"], int(str(r["key"]).rsplit("/", 1)[-1])))
    tmp = out / "episodes.jsonl.tmp"
    tmp.write_text("".join(json.dumps(r) + "\n" for r in rows))
    tmp.replace(out / "episodes.jsonl")
    summary = summarize(rows)
    summary["throughput/episodes_this_call"] = added
    summary["throughput/gpus"] = float(len(gpus))
    write_outputs(out, cfg, rows, summary, complete, run_dirs=[cells / t.name for t in tasks])
    report_window(rows, cfg.window)
    if failed:  # after the pooled outputs: what the other shares finished is kept
        logs = "; ".join(f"{r.name} exited with {r.returncode} (log {r.log})" for r in failed)
        raise RuntimeError(f"{len(failed)} of {len(results)} shares failed: {logs}. Fix the cause and rerun: "
                           "finished episodes are kept and each share resumes")  # fmt: skip
    return summary, complete
