"""One time-boxed chunk of PPO training on the GPU machine, resumed from the committed artifact.

    python scripts/gpu/train_chunk.py --run ppo_rft3d --contact-model rft3d --max-minutes 9 --out $OUT/ppo_rft3d

1. Seeds the run directory (``runs/gpu/<run>``, kept on a warm machine) from ``artifacts/<run>/`` when it has
   no checkpoint yet (a fresh machine): the newest ``checkpoint.pt`` and ``train_cfg.json``.
2. Calls :func:`gmloco.train.train` with ``max_minutes`` (it resumes from the newest checkpoint).
3. Writes to ``--out`` at most four files: ``checkpoint.pt`` (newest), ``policy.onnx``, ``summary.json``
   (metrics, config, this chunk's learning curve read from TensorBoard, timing) and ``log.txt`` is the
   caller's tee of stdout.

``scripts/gpu/collect_chunk.py`` (run here) merges a chunk into ``artifacts/<run>/``.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import time
from pathlib import Path
from typing import Any


def _parse() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--run", required=True, help="run name: artifacts/<run>/ and runs/gpu/<run>/")
    p.add_argument("--contact-model", required=True, choices=["rft3d", "heuristic_rft", "cone_multi", "rigid"])
    p.add_argument("--terrain", default="flat", choices=["flat", "rough", "deep"])
    p.add_argument("--num-envs", type=int, default=4096)
    p.add_argument("--max-iterations", type=int, default=30_000)
    p.add_argument("--max-minutes", type=float, default=9.0)
    p.add_argument("--seed", type=int, default=42)
    p.add_argument("--device", default="cuda:0")
    p.add_argument("--out", type=Path, required=True)
    return p.parse_args()


def _seed_run_dir(run_dir: Path, artifact: Path) -> int | None:
    """Copy the committed checkpoint into an empty run directory; return its iteration."""
    if any(run_dir.glob("model_*.pt")) or not (artifact / "checkpoint.pt").exists():
        return None
    import torch

    ckpt = torch.load(artifact / "checkpoint.pt", map_location="cpu", weights_only=False)
    it = int(ckpt["iter"])
    shutil.copy(artifact / "checkpoint.pt", run_dir / f"model_{it}.pt")
    if (artifact / "train_cfg.json").exists():
        shutil.copy(artifact / "train_cfg.json", run_dir / "train_cfg.json")
    return it


def _curve(run_dir: Path) -> dict[str, list[float]]:
    """Learning curve of this machine's TensorBoard events: iteration, reward, episode length, fps."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    tags = {
        "Train/mean_reward": "mean_reward",
        "Train/mean_episode_length": "mean_episode_length",
        "Perf/total_fps": "env_steps_per_s",
    }
    series: dict[int, dict[str, float]] = {}
    for events in sorted(run_dir.rglob("events.out.tfevents.*")):
        acc = EventAccumulator(str(events), size_guidance={"scalars": 0})
        acc.Reload()
        for tag, name in tags.items():
            if tag in acc.Tags()["scalars"]:
                for ev in acc.Scalars(tag):
                    series.setdefault(ev.step, {})[name] = ev.value
    its = sorted(series)
    out: dict[str, list[float]] = {"iteration": [float(i) for i in its]}
    for name in tags.values():
        out[name] = [series[i].get(name, float("nan")) for i in its]
    return out


def main() -> None:
    """Run one chunk and write the files that come back."""
    args = _parse()
    from gmloco.train import TrainRunCfg, g1_granular_task, train

    run_dir = Path("runs/gpu") / args.run
    run_dir.mkdir(parents=True, exist_ok=True)
    seeded = _seed_run_dir(run_dir, Path("artifacts") / args.run)
    cfg = TrainRunCfg(
        task=g1_granular_task(args.contact_model, args.terrain),
        num_envs=args.num_envs,
        max_iterations=args.max_iterations,
        max_minutes=args.max_minutes,
        seed=args.seed,
        device=args.device,
        run_dir=str(run_dir),
    )
    t0 = time.time()
    metrics = train(cfg)
    args.out.mkdir(parents=True, exist_ok=True)
    from gmloco.train.rl.runner import latest_checkpoint

    ckpt = latest_checkpoint(run_dir)
    if ckpt is not None:
        shutil.copy(ckpt, args.out / "checkpoint.pt")
    if (run_dir / "policy.onnx").exists():
        shutil.copy(run_dir / "policy.onnx", args.out / "policy.onnx")
    commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    summary: dict[str, Any] = {
        "run": args.run,
        "args": {k: str(v) for k, v in vars(args).items()},
        "seeded_from_artifact_iteration": seeded,
        "checkpoint": None if ckpt is None else ckpt.name,
        "metrics": metrics,
        "train_cfg": json.loads((run_dir / "train_cfg.json").read_text()),
        "curve": _curve(run_dir),
        "wall_s": time.time() - t0,
        "commit": commit or None,
    }
    import torch

    summary["device"] = torch.cuda.get_device_name(0) if torch.cuda.is_available() else "cpu"
    (args.out / "summary.json").write_text(json.dumps(summary, indent=1, default=str))
    print(json.dumps(metrics, indent=1, default=str))


if __name__ == "__main__":
    main()
