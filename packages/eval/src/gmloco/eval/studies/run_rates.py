# SPDX-License-Identifier: Apache-2.0
"""What a GPU run's MPM-evaluation runs cost, read back from their own records (issue 9).

Every episode line of an evaluation run holds its batch's solver rate (``frames_per_s``: MPM frames per second of
the whole batch), particle count, lanes and build time; a queue's ``queue.json`` holds each task's minutes and each
row's wall-clock over its shares (``g1.queue``). This module turns a study folder laid out as the GPU jobs
leave it (``runs/<task>/episodes.jsonl``, ``logs/queue.json``) into one ``throughput.json``:

* per run: episodes, particles, lanes, median solver frames/s, robot-frames/s with every lane stepping
  (frames/s x lanes), minutes per 100 ten-second walking episodes at that rate, scene build [s] and the task's
  minutes on its GPU;
* per row split into shares: the shares' GPUs, the row's wall-clock from the first share's start to the last
  one's end, its episodes and successes, and the longest time alive (a row's wall-clock follows its longest walk:
  fallen lanes take the next episode, but a batch ends with its last robot);
* per run, the solver rate by robots still walking (``by_running``): between two successive episode ends of one
  scene the lanes step together with a known number of robots left, so the records give the rate of a frame with
  25, 24, ... 1 robots, with or without idle lanes retired (``retire_idle_lanes`` from the run's ``summary.json``).

    python -m gmloco.eval.studies.run_rates results/mpm_eval/table_rows/ablation_circles [--out results/mpm_eval/table_rows/ablation_circles/throughput.json]
"""

from __future__ import annotations

import argparse
import json
import statistics
from collections import Counter
from pathlib import Path
from typing import Any

from gmloco.eval.g1.queue import share_row
from gmloco.eval.metrics.episodes import read_episodes

ROW_ROBOT_FRAMES = 100 * 10.0 / 0.005
"""Robot-frames of a row of 100 ten-second walking episodes at 5 ms frames."""
TARGET_ROBOT_FRAMES_PER_S = ROW_ROBOT_FRAMES / 600.0
"""Issue 9's target as a rate: such a row in 10 minutes [robot-frames/s]."""


def run_rate(episodes: list[dict[str, Any]]) -> dict[str, Any]:
    """Median solver rate, particles, lanes and build time of one run's episodes.

    The rate is read from the wall clock (``end_frame / elapsed_s``: frames of the batch over the wall seconds
    since its first frame) of the records that have it (the transition-course runs' code on; a run resumed from older records
    mixes both), else from ``frames_per_s`` (the scene's stepping clock, which until the square-window runs missed the GPU
    time waited in the grid-capacity checks and read ~8 % high at 4.4M particles); ``rate_clock`` says which.

    A run resumed across machines can hold batches of different widths (the time-box fit refits a late cell to
    the lanes that fit): the rate is that of its widest batches (most lanes), and ``other_lanes`` maps each
    narrower width to its episodes (``episodes`` counts them all), so a 3-lane batch's rate is never multiplied by 22 lanes.

    Raises:
        ValueError: no episodes, or an episode without the rate fields (a run older than the accepted-setting runs).
    """
    if not episodes:
        raise ValueError("no episodes: a run that finished none has no rate")
    for e in episodes:
        missing = {"frames_per_s", "batch_size", "particles", "build_s"} - set(e)
        if missing:
            raise ValueError(f"episode {e.get('key')!r} lacks {sorted(missing)}: not a batched g1_eval record")
    widths = Counter(e["batch_size"] for e in episodes)
    widest = max(widths)
    other = {str(w): n for w, n in widths.items() if w != widest}
    total = len(episodes)
    episodes = [e for e in episodes if e["batch_size"] == widest]
    timed = [e for e in episodes if has_wall_clock(e) and e["elapsed_s"] > 0]
    wall = bool(timed)
    fps = (
        statistics.median(e["end_frame"] / e["elapsed_s"] for e in timed)
        if wall
        else statistics.median(e["frames_per_s"] for e in episodes)
    )
    lanes = episodes[0]["batch_size"]
    rf = fps * lanes
    return {"episodes": total, "particles": episodes[0]["particles"], "lanes": lanes, "other_lanes": other,
            "rate_clock": "elapsed_s" if wall else "sim_s",
            "solver_frames_per_s_median": round(fps, 3), "robot_frames_per_s_all_lanes": round(rf, 1),
            "min_per_100_walking_episodes": round(ROW_ROBOT_FRAMES / rf / 60, 1), "build_s": round(episodes[0]["build_s"], 1)}  # fmt: skip


MIN_PIECE_S = 10.0
"""Shortest stretch of wall time ``running_rates`` rates on its own [s]: the scene's clock is read when a policy
step syncs the GPU, so a frame's time can land up to three frames late (~1 s at 3 cm)."""


def running_rates(episodes: list[dict[str, Any]], min_s: float = MIN_PIECE_S) -> dict[int, tuple[float, float]]:
    """MPM frames and wall seconds a run's scenes stepped with n robots walking: ``{n: (frames, seconds)}``.

    An episode record carries its scene's frame at its end (``end_frame``; before the transition-course runs
    ``sim_s * frames_per_s``) and the wall seconds since the scene's first frame (``elapsed_s``, host work
    included; before the transition-course runs only ``sim_s``, the time inside the scene's step, which misses the frames in flight
    while ended episodes are scored: up to three frames per end, so stretches with many ends read fast).
    Records of one scene are consecutive lines with one ``build_s``. Only scenes that recorded exactly
    ``batch_size`` episodes count: one batch, every lane's episode recorded, so after the k-th end (by its clock)
    ``batch_size - k`` robots were walking. A scene cut by a time box (its running episodes dropped unrecorded) or
    resumed with fewer episodes than lanes is left out, as is a scene whose lanes took queued episodes.
    Successive ends closer than ``min_s`` of wall time are merged into one stretch, labelled with its
    frame-weighted mean count of robots walking (rounded); a last stretch shorter than that is dropped.
    """
    out: dict[int, tuple[float, float]] = {}
    for scene in scenes(episodes):
        lanes = scene[0].get("batch_size")
        if lanes is None or len(scene) != lanes or "sim_s" not in scene[0]:
            continue
        t0 = f0 = last_f = wsum = 0.0
        for k, (t, f) in enumerate(sorted(_clock(e) for e in scene)):
            wsum += (lanes - k) * max(f - last_f, 0.0)
            last_f = max(f, last_f)
            if t - t0 >= min_s and f > f0:
                n = round(wsum / (f - f0))
                frames, secs = out.get(n, (0.0, 0.0))
                out[n] = (frames + f - f0, secs + t - t0)
                t0, f0, wsum = t, f, 0.0
    return dict(sorted(out.items(), reverse=True))


def scenes(episodes: list[dict[str, Any]]) -> list[list[dict[str, Any]]]:
    """A run's episode records split by the scene that ran them (consecutive records with one ``build_s``)."""
    out: list[list[dict[str, Any]]] = []
    for e in episodes:
        if out and out[-1][0].get("build_s") == e.get("build_s"):
            out[-1].append(e)
        else:
            out.append([e])
    return out


def has_wall_clock(e: dict[str, Any]) -> bool:
    """Whether an episode record carries ``elapsed_s`` / ``end_frame`` (the transition-course runs on)."""
    return e.get("elapsed_s") is not None and e.get("end_frame") is not None


def _clock(e: dict[str, Any]) -> tuple[float, float]:
    """(wall s, frame) of an episode's end: ``elapsed_s`` / ``end_frame`` where recorded, else from ``sim_s``."""
    if has_wall_clock(e):
        return float(e["elapsed_s"]), float(e["end_frame"])
    return float(e["sim_s"]), float(e["sim_s"] * e["frames_per_s"])


def _by_running(episodes: list[dict[str, Any]]) -> dict[str, float]:
    """``running_rates`` as ``{n: frames/s}`` with JSON keys, for ``throughput.json``."""
    return {str(n): round(f / s, 3) for n, (f, s) in running_rates(episodes).items()}


def retire_setting(run: Path) -> bool | None:
    """Whether a run retired idle lanes: its ``summary.json`` config (runs before the ablation-circle runs never did)."""
    path = run / "summary.json"
    if not path.is_file():
        return None
    return bool(json.loads(path.read_text()).get("cfg", {}).get("retire_idle_lanes", False))


def _task_minutes(queue: dict[str, Any]) -> dict[str, float]:
    """Minutes of each task that ran (the last entry wins when a task was restarted)."""
    return {t["name"]: t["minutes"] for t in queue.get("tasks", []) if t.get("minutes") is not None}


def folder_rates(folder: str | Path) -> dict[str, Any]:
    """``throughput.json``'s content for a study folder (``runs/``, optional ``logs/queue.json``, ``manifest.json``).

    Raises:
        FileNotFoundError: the folder has no ``runs/``.
    """
    root = Path(folder)
    if not (root / "runs").is_dir():
        raise FileNotFoundError(
            f"{root}: no runs/ folder; pass a study folder such as results/mpm_eval/table_rows/ablation_circles"
        )
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
        clock = "elapsed_s" if has_wall_clock(eps[0]) else "sim_s (in-step: reads fast near episode ends)"
        runs[run.name] = run_rate(eps) | {"task_minutes": minutes.get(run.name), "retire_idle_lanes": retire_setting(run),
                                          "by_running": _by_running(eps), "by_running_clock": clock}  # fmt: skip
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
    """Write a study folder's ``throughput.json`` and print its rates (see the module docstring)."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folder", help="study folder with runs/ (and logs/queue.json, manifest.json)")
    p.add_argument("--out", help="where to write the JSON (default: FOLDER/throughput.json)")
    a = p.parse_args(argv)
    out = folder_rates(a.folder)
    path = Path(a.out) if a.out else Path(a.folder) / "throughput.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    for name, r in out["runs"].items():
        print(f"{name}: {r['robot_frames_per_s_all_lanes']} robot-frames/s ({r['lanes']} lanes, {r['episodes']} ep)")
    for name, r in out["rows"].items():
        print(f"row {name}: {r['wall_minutes']} min on GPUs {' '.join(r['gpus'])}, {r['episodes']} episodes")
    print(f"-> {path}")


if __name__ == "__main__":
    main()
