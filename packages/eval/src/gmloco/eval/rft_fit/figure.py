# SPDX-License-Identifier: Apache-2.0
"""Figure of the MPM-fitted 3D-RFT: measured G against the published and the fitted set, per component."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

__all__ = ["fig_rft_fit"]


def fig_rft_fit(table: str | Path, path: str | Path) -> None:
    """Write the figure from ``plate_G.csv``: x = G of a set, y = G measured in MPM; one panel per component."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with Path(table).open() as f:
        rows = list(csv.DictReader(f))
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    for ax, c in zip(axes, "xyz", strict=True):
        mpm = np.array([float(r[f"G{c}_mpm"]) for r in rows])
        for key, color, label in (("prior", "tab:blue", "published (PNAS)"), ("fit", "tab:red", "fitted from MPM")):
            ax.scatter([float(r[f"G{c}_{key}"]) for r in rows], mpm, s=14, c=color, label=label)
        lim = float(np.max(np.abs(mpm))) * 1.2 + 1e-3
        ax.plot([-lim, lim], [-lim, lim], "k:", lw=0.8)
        ax.set(xlabel=f"G_{c} of the set [-]", ylabel=f"G_{c} measured in MPM [-]", title=f"G_{c}")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
