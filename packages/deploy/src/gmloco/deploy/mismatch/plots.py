# SPDX-License-Identifier: Apache-2.0
"""Report plots (matplotlib, imported lazily): heat map, overlays, residual vs regressor, intervals."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.mismatch.segmentation import PHASES

__all__ = ["make_plots"]


def make_plots(result: Any, out: Path) -> list[Path]:
    """Write the report figures into ``out``; return their paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a, paths = result.arrays, []
    names = a["names"]
    # 1. signal x phase heat map of the nominal residual energy (1 = noise floor)
    keys = sorted({n for n, _ in a["table"]}, key=names.index)[:58]
    labels = a.get("phase_labels", PHASES)
    mat = np.array([[a["table"].get((n, p), np.nan) for p in labels] for n in keys])
    fig, ax = plt.subplots(figsize=(5, 10))
    im = ax.imshow(np.log10(mat), aspect="auto", cmap="magma")
    ax.set_xticks(range(len(labels)), labels)
    ax.set_yticks(range(len(keys)), keys, fontsize=5)
    fig.colorbar(im, label="log10 residual energy / floor")
    paths.append(_save(fig, out / "heatmap.png"))
    # 2. overlays of real / nominal / fitted on the channels with the largest nominal residual
    r0 = (a["y"] - a["y0"]) / a["sigma"]
    top = np.argsort(-np.mean(r0**2, axis=(0, 1)))[:6]
    fig, axs = plt.subplots(len(top), 1, figsize=(9, 10), sharex=True)
    t = a["times"].ravel()
    o = np.argsort(t)
    for ax, c in zip(axs, top, strict=True):
        ax.plot(t[o], a["y"][..., c].ravel()[o], ".", ms=1.5, label="real")
        ax.plot(t[o], a["y0"][..., c].ravel()[o], ".", ms=1.5, label="nominal sim")
        ax.plot(t[o], a["y1"][..., c].ravel()[o], ".", ms=1.5, label="fitted sim")
        ax.set_ylabel(names[c], fontsize=6)
    axs[0].legend(fontsize=6)
    axs[-1].set_xlabel("t [s]")
    paths.append(_save(fig, out / "overlay_top6.png"))
    h = a.get("winner")
    if h is not None:
        # 3. residual vs the winning regressor (first component), and 4. parameter intervals
        s = h.sens[..., 0].ravel()  # screening sensitivities exist on the training segments only
        fig, ax = plt.subplots(figsize=(5, 4))
        ax.plot(s, r0[~a["held"]].ravel(), ",", alpha=0.3)
        ax.set_xlabel(f"sensitivity d y / d {h.spec.labels()[0]} (normalised)")
        ax.set_ylabel("nominal residual (normalised)")
        ax.set_title(h.spec.id)
        paths.append(_save(fig, out / "residual_vs_regressor.png"))
        fig, ax = plt.subplots(figsize=(5, 0.4 * h.spec.size + 1.5))
        y = np.arange(h.spec.size)
        ax.errorbar(h.theta, y, xerr=np.abs(h.ci.T - h.theta), fmt="o")
        ax.set_yticks(y, h.spec.labels(), fontsize=6)
        ax.axvline(0, color="k", lw=0.5)
        ax.set_title("fitted parameters, 95% CI")
        paths.append(_save(fig, out / "param_ci.png"))
    return paths


def _save(fig: Any, path: Path) -> Path:
    """Save and close a figure."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
