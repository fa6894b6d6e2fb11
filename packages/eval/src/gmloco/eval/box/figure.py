# SPDX-License-Identifier: Apache-2.0
"""Paper-style box-intrusion figure: travel vs sinkage per model, and GRF profiles (median over trials)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gmloco.eval.studies.study_io import StudyRecords

__all__ = ["MODEL_STYLE", "fig_box_intrusion"]

MODEL_STYLE: dict[str, tuple[str, str]] = {
    "mpm": ("black", "MPM (Newton)"),
    "rigid": ("tab:gray", "Rigid"),
    "heuristic_rft": ("tab:orange", "Heuristic-RFT"),
    "cone_single": ("tab:purple", "Cone-RFT-Single"),
    "cone_multi": ("tab:pink", "Cone-RFT-Multi"),
    "rft3d": ("tab:blue", "3D-RFT"),
    "rft3d_fitted": ("tab:cyan", "3D-RFT (fitted from MPM)"),
}
"""Colour and label of each model."""


def fig_box_intrusion(records: StudyRecords, mass: float, path: str | Path) -> None:
    """Write the figure: one column per variant; rows: travel-vs-sinkage, F_x(t), F_z(t), lateral F(t)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows, series = records.rows(), {(s["variant"], s["trial"], s["model"]): s for s in records.series()}
    variants = sorted({r["variant"] for r in rows}, key=lambda v: v != "forward")
    fig, axes = plt.subplots(4, len(variants), figsize=(5.5 * len(variants), 13), squeeze=False)
    weight = 9.81 * mass
    for col, variant in enumerate(variants):
        ax = axes[0, col]
        for model, (color, label) in MODEL_STYLE.items():
            rs = [r for r in rows if r["variant"] == variant and r["model"] == model]
            if rs:
                ax.scatter([100 * r["sinkage"] for r in rs], [r["travel"] for r in rs], s=14, c=color, label=label)
        ax.set(xlabel="final sinkage [cm]", ylabel="horizontal travel [m]", title=f"box at 1 m/s, {variant}")
        ax.legend(fontsize=7)
        for row, (comp, name) in enumerate(((0, "F_x"), (2, "F_z"), (1, "F_y (lateral)")), start=1):
            ax = axes[row, col]
            for model, (color, label) in MODEL_STYLE.items():
                ss = [s for (v, _t, m), s in series.items() if v == variant and m == model]
                if not ss:
                    continue
                n = min(len(s["grf"]) for s in ss)
                f = np.median(np.array([np.array(s["grf"])[:n, comp] for s in ss]), axis=0) / weight
                ax.plot(np.array(ss[0]["time"])[:n], f, c=color, lw=1.2, label=label)
            ax.set(xlabel="time [s]", ylabel=f"{name} / mg (median over trials)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
