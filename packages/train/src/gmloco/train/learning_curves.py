# SPDX-License-Identifier: Apache-2.0
"""Learning-curve figures of a teacher, student or PPO run from its logged curves.

A run's curves come as ``curve.csv`` (``scripts/gpu/collect_chunk.py``: all chunks merged) or as the ``curve`` of a
chunk's ``summary.json`` (``scripts/gpu/train_ts_chunk.py``). :func:`merge_curves` concatenates resumed chunks by
iteration (a later chunk wins where two logged the same iteration); :func:`fig_learning_curves` draws every panel
of :data:`PANELS` whose series the run logged.

    python -m gmloco.train.learning_curves artifacts/gm_loco_teacher_yaw --out artifacts/gm_loco_teacher_yaw/learning_curve.png
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

__all__ = ["PANELS", "chunk_starts", "fig_learning_curves", "merge_curves", "read_curve", "robust_ylim"]

Curve = dict[str, np.ndarray]
"""Column name -> values by row; ``iteration`` is sorted and unique."""

PANELS: tuple[tuple[str, tuple[str, ...], bool], ...] = (
    ("mean episode reward", ("mean_reward",), False),
    ("episode length [steps]", ("mean_episode_length",), False),
    ("learning rate", ("loss_learning_rate",), True),
    ("action std [-]", ("action_std",), False),
    ("eta R^2 (batch)", ("loss_eta_r2",), False),
    ("yaw tracking", ("yaw_rate_error", "heading_error", "reward_track_yaw_target", "reward_track_ang_vel_z"), False),
    ("hard floor depth, mean [m]", ("floor_depth_m",), False),
)
"""(y label, curve columns, log scale) per panel; a panel is drawn when one of its columns has a finite value."""


def _from_csv(path: Path) -> Curve:
    """Columns of a ``curve.csv`` (empty cells are NaN)."""
    with path.open() as f:
        rows = list(csv.DictReader(f))
    names = list(rows[0]) if rows else ["iteration"]
    return {n: np.array([float(r[n]) if r.get(n) not in ("", None) else math.nan for r in rows]) for n in names}


def _from_summary(path: Path) -> Curve:
    """The ``curve`` of a chunk's ``summary.json`` (null is NaN)."""
    curve = json.loads(path.read_text()).get("curve")
    if not isinstance(curve, dict) or "iteration" not in curve:
        raise ValueError(f"{path} has no 'curve' with an 'iteration' column")
    return {k: np.array([math.nan if v is None else float(v) for v in vals]) for k, vals in curve.items()}


def read_curve(source: str | Path) -> Curve:
    """Read a curve from ``curve.csv``, a ``summary.json``, or a folder holding one (``curve.csv`` first).

    Raises:
        ValueError: If ``source`` holds no curve.
    """
    path = Path(source)
    if path.is_dir():
        for name in ("curve.csv", "summary.json"):
            if (path / name).is_file():
                return read_curve(path / name)
        raise ValueError(f"{path} holds neither curve.csv nor summary.json; pass a run folder under artifacts/")
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    curve = _from_csv(path) if path.suffix == ".csv" else _from_summary(path)
    return merge_curves([curve])


def merge_curves(curves: Sequence[Curve]) -> Curve:
    """Concatenate curves by iteration; on a repeated iteration the later curve's row wins (a resumed chunk).

    Columns are the union; a value a curve did not log is NaN.
    """
    rows: dict[int, dict[str, float]] = {}
    columns: list[str] = ["iteration"]
    for curve in curves:
        columns += [c for c in curve if c not in columns]
        for i, it in enumerate(curve["iteration"]):
            rows[int(it)] = {k: float(v[i]) for k, v in curve.items()}
    order = sorted(rows)
    return {c: np.array([rows[it].get(c, math.nan) for it in order], dtype=np.float64) for c in columns}


def chunk_starts(manifest: str | Path) -> list[float]:
    """Iterations where a resumed chunk of ``manifest.json`` started (``resumed_from_iteration`` > 0)."""
    path = Path(manifest)
    if not path.is_file():
        return []
    chunks = json.loads(path.read_text()).get("chunks", [])
    return sorted({float(c["resumed_from_iteration"]) for c in chunks if c.get("resumed_from_iteration")})


def robust_ylim(values: np.ndarray, spread: float = 3.0) -> tuple[float, float, int] | None:
    """Y limits that keep a few blown-up points (a diverged iteration's -1e11 reward) from flattening a panel.

    The limits are the 1st-99th percentile range widened by ``spread`` times its width on each side. Returns
    ``(low, high, points outside)``, or None when every finite value lies inside (the axis then autoscales).
    """
    finite = values[np.isfinite(values)]
    if finite.size < 10:
        return None
    lo, hi = np.percentile(finite, [1.0, 99.0])
    width = max(hi - lo, 1e-12)
    low, high = lo - spread * width, hi + spread * width
    outside = int(np.count_nonzero((finite < low) | (finite > high)))
    return (float(low), float(high), outside) if outside else None


def fig_learning_curves(curve: Curve, path: str | Path, title: str, starts: Sequence[float] = ()) -> list[str]:
    """Draw the panels of :data:`PANELS` the curve has against iteration; dashed lines at chunk ``starts``.

    The PNG is written through a temporary file (never half a file). Returns the y labels of the drawn panels.

    Raises:
        ValueError: If the curve has none of the panels' columns.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    present = [
        (label, [c for c in cols if c in curve and np.isfinite(curve[c]).any()], log) for label, cols, log in PANELS
    ]
    present = [p for p in present if p[1]]
    if not present:
        raise ValueError(f"the curve has none of {[c for _, cols, _ in PANELS for c in cols]}")
    ncols = min(3, len(present))
    nrows = math.ceil(len(present) / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.3 * ncols, 2.4 * nrows), squeeze=False, constrained_layout=True)
    it = curve["iteration"]
    for ax, (label, cols, log) in zip(axes.flat, present, strict=False):
        for c in cols:
            ok = np.isfinite(curve[c])
            ax.plot(it[ok], curve[c][ok], lw=0.8, label=c if len(cols) > 1 else None)
        ax.set(xlabel="iteration", ylabel=label, yscale="log" if log else "linear")
        limits = None if log else robust_ylim(np.concatenate([curve[c] for c in cols]))
        if limits is not None:
            ax.set_ylim(limits[0], limits[1])
            ax.text(0.02, 0.03, f"{limits[2]} point(s) off scale", transform=ax.transAxes, fontsize=6, color="C3")
        if len(cols) > 1:
            ax.legend(fontsize=6)
        for x in starts:
            ax.axvline(x, ls="--", lw=0.6, color="0.5")
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(present) :]:
        ax.set_visible(False)
    fig.suptitle(title + ("  (dashed: resumed chunks)" if starts else ""), fontsize=9)
    out = Path(path)
    tmp = out.with_name(f".{out.stem}.tmp.png")
    fig.savefig(tmp, dpi=80)
    plt.close(fig)
    os.replace(tmp, out)
    return [label for label, _, _ in present]


def main(argv: Sequence[str] | None = None) -> int:
    """Merge the given sources and draw the figure; return the exit code (2: bad input).

    Chunk starts come from the ``manifest.json`` beside the last source (the run the figure is for).
    """
    p = argparse.ArgumentParser(
        prog="python -m gmloco.train.learning_curves", description=(__doc__ or "").splitlines()[0]
    )
    p.add_argument("sources", nargs="+", help="run folders, curve.csv or chunk summary.json files, oldest first")
    p.add_argument("--out", required=True, help="PNG to write, e.g. artifacts/<run>/learning_curve.png")
    p.add_argument("--title", default=None, help="figure title (default: the last source's folder name)")
    args = p.parse_args(argv)
    last = Path(args.sources[-1])
    folder = last if last.is_dir() else last.parent
    try:
        curve = merge_curves([read_curve(s) for s in args.sources])
        drawn = fig_learning_curves(curve, args.out, args.title or folder.name, chunk_starts(folder / "manifest.json"))
    except ValueError as err:
        print(f"learning_curves: {err}", file=sys.stderr)
        return 2
    print(f"{args.out}: {len(curve['iteration'])} iterations, panels {drawn}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
