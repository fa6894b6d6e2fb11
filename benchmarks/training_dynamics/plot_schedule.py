"""Learning rate, action std and mean reward per PPO iteration, several runs side by side.

    python benchmarks/training_dynamics/plot_schedule.py \
        --bench stock=results/training_dynamics/action_scale_ab/stock.json \
        --bench uniform_0.25=results/training_dynamics/action_scale_ab/uniform.json \
        --summary teacher_from_scratch=artifacts/gm_loco_teacher_yaw/summary.json --iterations 150 \
        --out results/training_dynamics/action_scale_ab/schedule.png

``--bench`` reads a ``benchmarks/gpu/bench_tasks.py`` JSON (its one task's ``curve``); ``--summary`` reads a
``train_ts_chunk.py`` summary (``curve`` with ``loss_learning_rate``, ``action_std``, ``mean_reward``). Each
run is drawn over its first ``--iterations`` iterations. Exit 2 on a missing file or key.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

_PANELS = (("learning_rate", "learning rate (last mini-batch)"), ("action_std", "action std [-]"),
           ("mean_reward", "mean episode reward"))  # fmt: skip
_SUMMARY_KEYS = {"learning_rate": "loss_learning_rate", "action_std": "action_std", "mean_reward": "mean_reward"}


def _pair(item: str) -> tuple[str, Path]:
    label, sep, path = item.partition("=")
    if not sep or not label or not path:
        raise argparse.ArgumentTypeError(f"{item!r}: expected LABEL=PATH")
    return label, Path(path)


def bench_curve(path: Path) -> dict[str, list[float]]:
    """The per-iteration curve of the single task in a bench_tasks JSON."""
    tasks = json.loads(path.read_text())["tasks"]
    if len(tasks) != 1:
        raise KeyError(f"{path}: expected one task, found {sorted(tasks)}")
    return next(iter(tasks.values()))["curve"]


def summary_curve(path: Path) -> dict[str, list[float]]:
    """The same three series from a train_ts_chunk summary."""
    curve = json.loads(path.read_text())["curve"]
    return {key: curve[src] for key, src in _SUMMARY_KEYS.items()}


def main(argv: list[str] | None = None) -> None:
    """Draw the runs into one figure."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bench", type=_pair, action="append", default=[], metavar="LABEL=PATH")
    p.add_argument("--summary", type=_pair, action="append", default=[], metavar="LABEL=PATH")
    p.add_argument("--iterations", type=int, default=150)
    p.add_argument("--out", type=Path, required=True)
    args = p.parse_args(argv)
    runs: list[tuple[str, dict[str, list[float]]]] = []
    try:
        runs += [(label, bench_curve(path)) for label, path in args.bench]
        runs += [(label, summary_curve(path)) for label, path in args.summary]
    except (OSError, KeyError, ValueError) as err:
        print(f"cannot read a run: {err}", file=sys.stderr)
        sys.exit(2)
    if not runs:
        p.error("give at least one --bench or --summary")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.4))
    for label, curve in runs:
        for ax, (key, _) in zip(axes, _PANELS, strict=True):
            ys = curve[key][: args.iterations]
            ax.plot(range(len(ys)), ys, lw=1, label=label)
    for ax, (key, title) in zip(axes, _PANELS, strict=True):
        ax.set_xlabel("iteration")
        ax.set_ylabel(title)
        ax.grid(alpha=0.3)
        if key == "learning_rate":
            ax.set_yscale("log")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"{args.out}: {len(runs)} runs")


if __name__ == "__main__":
    main()
