# SPDX-License-Identifier: Apache-2.0
"""Figures of the sand calibration: force-depth per experiment, held-out error per term, predicted vs MPM success."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gmloco.eval.calibration.dataset import CalibrationDataset

__all__ = ["fig_force_depth", "fig_predicted_success", "fig_term_errors"]


def fig_force_depth(ds: CalibrationDataset, models: dict[str, dict[str, np.ndarray]], path: str | Path) -> Path:
    """Write vertical (solid) and horizontal (dotted) force [N] against depth [m] per experiment.

    Args:
        ds: The dataset (its sand is drawn in black, labelled by its source).
        models: Replayed force [N] [T, 3] per record name, per model label (e.g. ``3D-RFT``, ``calibrated``).
        path: PNG to write.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(ds.records)
    cols = min(4, len(names))
    rows = -(-len(names) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.0 * rows), squeeze=False)
    series = {ds.source: {n: r.force for n, r in ds.records.items()}, **models}
    colors = ["k", "tab:blue", "tab:red", "tab:green"]
    for ax, name in zip(axes.flat, names, strict=False):
        depth = 100.0 * ds.records[name].depth
        for (label, forces), color in zip(series.items(), colors, strict=False):
            f = forces[name]
            wide = 2.5 if label == ds.source else 1.0  # the sand under the models that may cover it
            ax.plot(depth, f[:, 2], color=color, lw=wide, alpha=0.5 if wide > 1 else 1.0, label=f"{label} F_z")
            ax.plot(depth, np.hypot(f[:, 0], f[:, 1]), color=color, lw=0.8, ls=":", label=f"{label} |F_xy|")
        ax.set(title=f"{name} ({ds.split[name]})", xlabel="depth of the sole's lowest point [cm]", ylabel="force [N]")
    for ax in list(axes.flat)[len(names) :]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=6)
    fig.suptitle(f"{ds.material}: sand force on the G1 sole")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return Path(path)


def fig_term_errors(verdicts: dict[str, Any], path: str | Path) -> Path:
    """Write the held-out RMS force error [N] of each term's variants (with, without, alone) as grouped bars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    terms = list(verdicts["terms"])
    rows = [verdicts["terms"][t] for t in terms]
    x = np.arange(len(terms))
    fig, ax = plt.subplots(figsize=(1.6 * len(terms) + 2.5, 3.6))
    for k, (key, label) in enumerate(
        (("heldout_with_N", "all terms"), ("heldout_without_N", "all but this"), ("heldout_alone_N", "this alone"))
    ):
        ax.bar(x + (k - 1) * 0.26, [r[key] for r in rows], 0.26, label=label)
    ax.axhline(verdicts["published"]["heldout"], color="k", ls="--", lw=0.8, label="3D-RFT (published)")
    ax.set_xticks(x, [f"{t}\n{r['verdict']}" for t, r in zip(terms, rows, strict=True)], fontsize=7)
    ax.set(ylabel="held-out RMS force error [N]", title=f"{verdicts['material']}: extension terms")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return Path(path)


def fig_predicted_success(policy: str, table: dict[str, Any], path: str | Path, band: float = 15.0) -> Path:
    """Write MPM and predicted success [%] against commanded speed [m/s], one panel per material.

    Args:
        policy: Policy name (the title).
        table: ``{material: {speed key: cell}}`` of ``gmloco.eval.calibration.predict`` (MPM and each model's).
        path: PNG to write.
        band: Half-width of the shaded tolerance around MPM [percentage points].
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    materials = list(table)
    fig, axes = plt.subplots(1, len(materials), figsize=(3.6 * len(materials), 3.2), squeeze=False, sharey=True)
    for ax, material in zip(axes.flat, materials, strict=True):
        keys = list(table[material])
        v = np.array([float(k) for k in keys])
        mpm = np.array([table[material][k]["mpm_success_pct"] for k in keys])
        ax.fill_between(v, mpm - band, mpm + band, color="k", alpha=0.1, lw=0, label=f"MPM +/- {band:g} points")
        ax.plot(v, mpm, "k-o", lw=2.0, label="MPM")
        models = sorted({m for k in keys for m in table[material][k]["predicted_success_pct"]})
        for model in models:
            pred = [table[material][k]["predicted_success_pct"].get(model) for k in keys]
            y = np.array([np.nan if p is None else p for p in pred], dtype=float)
            ax.plot(v, y, "--s", lw=1.2, label=f"training sim, {model}")
        ax.set(title=material, xlabel="commanded speed [m/s]", ylim=(-5.0, 105.0))
    axes.flat[0].set_ylabel("success [%]")
    axes.flat[0].legend(fontsize=6)
    fig.suptitle(f"{policy}: success on MPM and as predicted")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return Path(path)
