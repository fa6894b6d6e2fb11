# SPDX-License-Identifier: Apache-2.0
"""What a GPU session's MPM-evaluation runs cost, read back from their own records (issue 9).

Every episode line of a ``g1_eval`` run holds its batch's solver rate (``frames_per_s``: MPM frames per second of
the whole batch), particle count, lanes and build time; a queue's ``queue.json`` holds each task's minutes and each
row's wall-clock over its shares (``g1_eval_queue``). This module turns a session folder laid out as the GPU jobs
leave it (``runs/<task>/episodes.jsonl``, ``logs/queue.json``) into one ``throughput.json``:

* per run: episodes, particles, lanes, median solver frames/s, robot-frames/s with every lane stepping
  (frames/s x lanes), minutes per 100 ten-second walking episodes at that rate, scene build [s] and the task's
  minutes on its GPU;
* per row split into shares: the shares' GPUs, the row's wall-clock from the first share's start to the last
  one's end, its episodes and successes, and the longest time alive (a row's wall-clock follows its longest walk:
  fallen lanes take the next episode, but a batch ends with its last robot).

    python -m gmloco.eval.run_rates results/mpm_eval/gpu_s18 [--out results/mpm_eval/gpu_s18/throughput.json]
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path
from typing import Any

from gmloco.eval.g1_eval import read_episodes
from gmloco.eval.g1_eval_queue import share_row

ROW_ROBOT_FRAMES = 100 * 10.0 / 0.005
"""Robot-frames of a row of 100 ten-second walking episodes at 5 ms frames."""
TARGET_ROBOT_FRAMES_PER_S = ROW_ROBOT_FRAMES / 600.0
"""Issue 9's target as a rate: such a row in 10 minutes [robot-frames/s]."""


def run_rate(episodes: list[dict[str, Any]]) -> dict[str, Any]:
    """Median solver rate, particles, lanes and build time of one run's episodes.

    Raises:
        ValueError: no episodes, or an episode without the rate fields (a run older than session 12).
    """
    if not episodes:
        raise ValueError("no episodes: a run that finished none has no rate")
    missing = {"frames_per_s", "batch_size", "particles", "build_s"} - set(episodes[0])
    if missing:
        raise ValueError(f"episode {episodes[0].get('key')!r} lacks {sorted(missing)}: not a batched g1_eval record")
    fps = statistics.median(e["frames_per_s"] for e in episodes)
    lanes = episodes[0]["batch_size"]
    rf = fps * lanes
    return {"episodes": len(episodes), "particles": episodes[0]["particles"], "lanes": lanes,
            "solver_frames_per_s_median": round(fps, 3), "robot_frames_per_s_all_lanes": round(rf, 1),
            "min_per_100_walking_episodes": round(ROW_ROBOT_FRAMES / rf / 60, 1), "build_s": round(episodes[0]["build_s"], 1)}  # fmt: skip


def _task_minutes(queue: dict[str, Any]) -> dict[str, float]:
    """Minutes of each task that ran (the last entry wins when a task was restarted)."""
    return {t["name"]: t["minutes"] for t in queue.get("tasks", []) if t.get("minutes") is not None}


def session_rates(folder: str | Path) -> dict[str, Any]:
    """``throughput.json``'s content for a session folder (``runs/``, optional ``logs/queue.json``, ``manifest.json``).

    Raises:
        FileNotFoundError: the folder has no ``runs/``.
    """
    root = Path(folder)
    if not (root / "runs").is_dir():
        raise FileNotFoundError(f"{root}: no runs/ folder; pass a session folder such as results/mpm_eval/gpu_s18")
    qpath = root / "logs" / "queue.json"
    queue = json.loads(qpath.read_text()) if qpath.is_file() else {}
    minutes = _task_minutes(queue)
    manifest = json.loads((root / "manifest.json").read_text()) if (root / "manifest.json").is_file() else {}
    runs: dict[str, Any] = {}
    episodes: dict[str, list[dict[str, Any]]] = {}
    for run in sorted(p for p in (root / "runs").iterdir() if (p / "episodes.jsonl").is_file()):
        eps = read_episodes(run / "episodes.jsonl")
        if not eps:
            continue
        episodes[run.name] = eps
        runs[run.name] = run_rate(eps) | {"task_minutes": minutes.get(run.name)}
    rows = {}
    for name, row in queue.get("rows", {}).items():
        shares = [eps for run, eps in episodes.items() if share_row(run) == name]
        pooled = [e for eps in shares for e in eps]
        rows[name] = {"shares": row["shares"], "gpus": row["gpus"], "wall_minutes": row["wall_minutes"],
                      "episodes": len(pooled), "successes": sum(bool(e["success"]) for e in pooled),
                      "longest_alive_s": max((e["alive_s"] for e in pooled), default=None),
                      "build_s_max": max((eps[0]["build_s"] for eps in shares), default=None)}  # fmt: skip
    return {"device": manifest.get("device"), "code": manifest.get("code"),
            "target_robot_frames_per_s": round(TARGET_ROBOT_FRAMES_PER_S, 1), "runs": runs, "rows": rows}  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    """Write a session folder's ``throughput.json`` and print its rates (see the module docstring)."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folder", help="session folder with runs/ (and logs/queue.json, manifest.json)")
    p.add_argument("--out", help="where to write the JSON (default: FOLDER/throughput.json)")
    a = p.parse_args(argv)
    out = session_rates(a.folder)
    path = Path(a.out) if a.out else Path(a.folder) / "throughput.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    for name, r in out["runs"].items():
        print(f"{name}: {r['robot_frames_per_s_all_lanes']} robot-frames/s ({r['lanes']} lanes, {r['episodes']} ep)")
    for name, r in out["rows"].items():
        print(f"row {name}: {r['wall_minutes']} min on GPUs {' '.join(r['gpus'])}, {r['episodes']} episodes")
    print(f"-> {path}")


if __name__ == "__main__":
    main()
