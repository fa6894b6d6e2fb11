"""Merge one GPU training chunk (the files ``train_chunk.py`` brought back) into ``artifacts/<run>/``.

    python scripts/gpu/collect_chunk.py --chunk /path/to/device/out/ppo_rft3d --run ppo_rft3d \
        --commit d769e17 --gpu-minutes 21.4

``artifacts/<run>/`` then holds: ``checkpoint.pt`` (newest; the next chunk resumes from it), ``policy.onnx``,
``metrics.json`` (newest chunk's metrics), ``curve.csv`` (all chunks, by iteration), ``learning_curve.png`` and
``manifest.json`` (one entry per chunk: commit, device, config, iterations, GPU minutes; totals).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import shutil
from pathlib import Path
from typing import Any

_COLUMNS = ("iteration", "mean_reward", "mean_episode_length", "env_steps_per_s")


def _parse() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--chunk", type=Path, required=True, help="folder with summary.json, checkpoint.pt, ...")
    p.add_argument("--run", required=True)
    p.add_argument("--commit", required=True, help="git commit the GPU machine's tree was at")
    p.add_argument("--gpu-minutes", type=float, required=True, help="GPU wall minutes this chunk held")
    p.add_argument("--note", default="", help="free text stored with the chunk (e.g. shared the GPU)")
    p.add_argument("--artifacts", type=Path, default=Path("artifacts"))
    return p.parse_args()


def _write_json(path: Path, data: Any) -> None:
    """Write JSON atomically (tmp + os.replace)."""
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(json.dumps(data, indent=1, default=str))
    os.replace(tmp, path)


def _merge_curve(path: Path, new: dict[str, list[float]]) -> list[dict[str, float]]:
    """Rows of the old curve plus the chunk's, the chunk winning on repeated iterations.

    Columns are the union of the old file's and the chunk's (e.g. the teacher's loss curves); a value a chunk did
    not log is NaN.
    """
    rows: dict[int, dict[str, float]] = {}
    columns = list(_COLUMNS)
    if path.exists():
        with path.open() as f:
            reader = csv.DictReader(f)
            columns += [c for c in reader.fieldnames or () if c not in columns]
            for r in reader:
                rows[int(float(r["iteration"]))] = {k: float(v) for k, v in r.items() if v not in ("", None)}
    columns += [c for c in new if c not in columns]
    for i, it in enumerate(new["iteration"]):
        rows[int(it)] = {k: float(v[i]) if v[i] is not None else math.nan for k, v in new.items()}
    ordered = [{k: rows[it].get(k, math.nan) for k in columns} for it in sorted(rows)]
    tmp = path.with_suffix(".csv.tmp")
    with tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns)
        w.writeheader()
        w.writerows(ordered)
    os.replace(tmp, path)
    return ordered


def _plot(dest: Path, title: str) -> None:
    """``learning_curve.png`` of the merged ``curve.csv`` (``gmloco.train.learning_curves``; dashed: chunk starts)."""
    from gmloco.train.learning_curves import chunk_starts, fig_learning_curves, read_curve

    fig_learning_curves(
        read_curve(dest / "curve.csv"), dest / "learning_curve.png", title, chunk_starts(dest / "manifest.json")
    )


def main() -> None:
    """Merge the chunk."""
    args = _parse()
    summary = json.loads((args.chunk / "summary.json").read_text())
    dest = args.artifacts / args.run
    dest.mkdir(parents=True, exist_ok=True)
    for name in ("checkpoint.pt", "policy.onnx", "policy.json"):
        if (args.chunk / name).exists():
            shutil.copy(args.chunk / name, dest / f"{name}.tmp")
            os.replace(dest / f"{name}.tmp", dest / name)
    _write_json(dest / "train_cfg.json", summary["train_cfg"])
    metrics = {k: (v if not isinstance(v, float) or math.isfinite(v) else None) for k, v in summary["metrics"].items()}
    _write_json(dest / "metrics.json", metrics)
    if summary.get("checks"):
        _write_json(dest / "checks.json", summary["checks"])  # teacher-student: eta R2, parity, action error
    if summary.get("last_values"):
        _write_json(dest / "last_values.json", summary["last_values"])  # per-term rewards, terminations, curricula
    _merge_curve(dest / "curve.csv", summary["curve"])
    manifest_path = dest / "manifest.json"
    manifest = json.loads(manifest_path.read_text()) if manifest_path.exists() else {"run": args.run, "chunks": []}
    manifest["chunks"].append(
        {
            "commit": args.commit,
            "device": summary.get("device"),
            "command": f"python3 {summary.get('script', 'scripts/gpu/train_chunk.py')} "
            + " ".join(f"--{k} {v}" for k, v in summary["args"].items()),
            "resumed_from_iteration": metrics.get("resumed_from_iteration"),
            "iteration": metrics.get("iteration"),
            "gpu_minutes": args.gpu_minutes,
            "wall_s": summary.get("wall_s"),
            "note": args.note,
        }
    )
    manifest["iteration"] = metrics.get("iteration")
    manifest["gpu_minutes_total"] = sum(c["gpu_minutes"] for c in manifest["chunks"])
    manifest["train_cfg"] = "train_cfg.json"
    script = summary.get("script", "scripts/gpu/train_chunk.py")
    manifest["produced_by"] = f"{script} on the GPU machine, merged by scripts/gpu/collect_chunk.py"
    _write_json(manifest_path, manifest)
    _plot(dest, args.run)
    print(f"{dest}: iteration {manifest['iteration']}, {manifest['gpu_minutes_total']:.1f} GPU-minutes in total")


if __name__ == "__main__":
    main()
