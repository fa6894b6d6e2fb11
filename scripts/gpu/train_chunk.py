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
from dataclasses import replace
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
    p.add_argument(
        "--curriculum-scale",
        type=float,
        default=None,
        help="GranularTaskCfg.curriculum_scale (None: keep the task default / the run's saved config)",
    )
    p.add_argument(
        "--weights-only",
        action="store_true",
        help="start a new run (new task config) from the artifact's policy weights instead of resuming it",
    )
    p.add_argument("--out", type=Path, required=True)
    p.add_argument(
        "--gpus",
        type=int,
        nargs="+",
        default=[],
        help="CUDA device ids trained on data-parallel, one rank each (TrainRunCfg.gpus); default: --device alone",
    )
    args = p.parse_args()
    if args.gpus:
        from gmloco.train.multi_gpu import cuda_device_count, gpus_problem

        if (problem := gpus_problem(args.gpus, cuda_device_count())) is not None:
            p.error(f"--gpus {' '.join(map(str, args.gpus))}: {problem}")
    return args


def _seed_run_dir(run_dir: Path, artifact: Path, weights_only: bool) -> tuple[int | None, str | None]:
    """Seed an empty run directory from the committed checkpoint.

    Returns the artifact's iteration and, with ``weights_only``, the checkpoint to pass as ``init_checkpoint``
    (a new run whose task config differs; the checkpoint's curriculum counter is not restored then).
    """
    if any(run_dir.glob("model_*.pt")) or not (artifact / "checkpoint.pt").exists():
        return None, None
    import torch

    ckpt = torch.load(artifact / "checkpoint.pt", map_location="cpu", weights_only=False)
    it = int(ckpt["iter"])
    if weights_only:
        ckpt["infos"] = {k: v for k, v in (ckpt.get("infos") or {}).items() if k != "env_state"}
        init = run_dir.parent / f"{run_dir.name}_init.pt"
        torch.save(ckpt, init)
        return it, str(init)
    shutil.copy(artifact / "checkpoint.pt", run_dir / f"model_{it}.pt")
    if (artifact / "train_cfg.json").exists():
        shutil.copy(artifact / "train_cfg.json", run_dir / "train_cfg.json")
    return it, None


_CURVE_TAGS = {
    "Train/mean_reward": "mean_reward",
    "Train/mean_episode_length": "mean_episode_length",
    "Perf/total_fps": "env_steps_per_s",
}
"""TensorBoard tags of the learning curve and their column names."""
_LAST_VALUE_PREFIXES = ("Episode_Reward/", "Episode_Termination/", "Curriculum/", "Metrics/", "Loss/", "Policy/")
"""TensorBoard tag families whose last-10-iteration means go into the summary (per-term diagnosis)."""


def _scalars(run_dir: Path) -> dict[str, dict[int, float]]:
    """Every scalar of this machine's TensorBoard events, ``{tag: {step: value}}`` (one read of the files)."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    values: dict[str, dict[int, float]] = {}
    for events in sorted(run_dir.rglob("events.out.tfevents.*")):
        acc = EventAccumulator(str(events), size_guidance={"scalars": 0})
        acc.Reload()
        for tag in acc.Tags()["scalars"]:
            values.setdefault(tag, {}).update({ev.step: ev.value for ev in acc.Scalars(tag)})
    return values


def _curve(scalars: dict[str, dict[int, float]]) -> dict[str, list[float]]:
    """Learning curve: iteration, reward, episode length, fps (NaN where a tag was not logged)."""
    its = sorted({step for tag in _CURVE_TAGS for step in scalars.get(tag, {})})
    out: dict[str, list[float]] = {"iteration": [float(i) for i in its]}
    for tag, name in _CURVE_TAGS.items():
        out[name] = [scalars.get(tag, {}).get(i, float("nan")) for i in its]
    return out


def _last_values(scalars: dict[str, dict[int, float]], window: int = 10) -> dict[str, float]:
    """Mean of the last ``window`` logged values of every per-term tag (reward terms, terminations, curricula)."""
    out = {}
    for tag, series in sorted(scalars.items()):
        if tag.startswith(_LAST_VALUE_PREFIXES):
            last = [series[k] for k in sorted(series)[-window:]]
            out[tag] = sum(last) / len(last)
    return out


def main() -> None:
    """Run one chunk and write the files that come back."""
    args = _parse()
    from gmloco.train import TrainRunCfg, g1_granular_task, train

    run_dir = Path("runs/gpu") / args.run
    run_dir.mkdir(parents=True, exist_ok=True)
    seeded, init = _seed_run_dir(run_dir, Path("artifacts") / args.run, args.weights_only)
    task = g1_granular_task(args.contact_model, args.terrain)
    saved_cfg = run_dir / "train_cfg.json"
    if args.curriculum_scale is not None:
        task = replace(task, curriculum_scale=args.curriculum_scale)
    elif saved_cfg.exists():
        task = replace(task, curriculum_scale=json.loads(saved_cfg.read_text())["task"].get("curriculum_scale", 1.0))
    cfg = TrainRunCfg(
        task=task,
        init_checkpoint=init,
        num_envs=args.num_envs,
        max_iterations=args.max_iterations,
        max_minutes=args.max_minutes,
        seed=args.seed,
        device=args.device,
        gpus=tuple(args.gpus),
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
        "script": "scripts/gpu/train_chunk.py",
        "run": args.run,
        "args": {k: str(v) for k, v in vars(args).items()},
        "seeded_from_artifact_iteration": seeded,
        "checkpoint": None if ckpt is None else ckpt.name,
        "metrics": metrics,
        "train_cfg": json.loads((run_dir / "train_cfg.json").read_text()),
        "curve": _curve(scalars := _scalars(run_dir)),
        "last_values": _last_values(scalars),
        "wall_s": time.time() - t0,
        "commit": commit or None,
    }
    import torch

    summary["device"] = torch.cuda.get_device_name(0) if torch.cuda.is_available() else "cpu"
    (args.out / "summary.json").write_text(json.dumps(summary, indent=1, default=str))
    print(json.dumps(metrics, indent=1, default=str))


if __name__ == "__main__":
    main()
