# SPDX-License-Identifier: Apache-2.0
"""Paper-style figures of the log analyses (matplotlib, imported lazily, Agg backend)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType

    from gmloco.deploy.logs.analysis.run_analysis import RunAnalysis

__all__ = ["fig_ankle_torque", "fig_clearance", "fig_eta", "fig_gait", "fig_velocity_tracking", "write_figures"]

_STYLE: dict[RcKeyType, Any] = {"font.size": 8, "axes.spines.top": False, "axes.spines.right": False, "figure.dpi": 150}


def _plt() -> Any:
    """Import pyplot with a non-interactive backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plt.rcParams.update(_STYLE)
    return plt


def _label(r: RunAnalysis) -> str:
    """Legend label of a run."""
    return f"{r.summary['controller']} / {r.summary['material']} ({r.summary['file']})"


def _legend_below(ax: Any) -> None:
    """Legend under the axes, clear of the data, with room made for it (run labels carry file names, long)."""
    ax.figure.set_layout_engine("constrained")
    ax.figure.legend(fontsize=5, loc="outside lower left", frameon=False)


def fig_velocity_tracking(runs: list[RunAnalysis], path: Path) -> Path:
    """Measured vs commanded forward speed, one marker per command segment, per controller."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(3.4, 3.0))
    for r in runs:
        rows = r.tracking
        if rows:
            c = [x["cmd"] for x in rows]
            ax.errorbar(
                c,
                [x["v_mean"] for x in rows],
                yerr=[x["v_std"] for x in rows],
                fmt="o",
                ms=4,
                capsize=2,
                label=f"{_label(r)} [{r.summary['velocity_source']}]",
            )
    lim = [min(ax.get_xlim()[0], ax.get_ylim()[0]), max(ax.get_xlim()[1], ax.get_ylim()[1])]
    ax.plot(lim, lim, "k--", lw=0.8, label="ideal")
    ax.set(xlabel="commanded $v_x$ [m/s]", ylabel="measured $v_x$ [m/s]", title="Velocity tracking")
    _legend_below(ax)
    return _save(fig, path)


def fig_ankle_torque(runs: list[RunAnalysis], path: Path) -> Path:
    """Ankle-pitch torque over normalized stance (mean +- std over stances), per run."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(3.4, 2.6))
    for r in runs:
        prof = r.series["ankle_profiles"]
        if len(prof):
            x = np.linspace(0, 100, prof.shape[1])
            m, s = prof.mean(0), prof.std(0)
            (line,) = ax.plot(x, m, lw=1.2, label=f"{_label(r)} (n={len(prof)})")
            ax.fill_between(x, m - s, m + s, color=line.get_color(), alpha=0.2)
    ax.set(xlabel="stance [%]", ylabel="ankle pitch $\\tau_{est}$ [N m]", title="Ankle-pitch torque during stance")
    _legend_below(ax)
    return _save(fig, path)


def fig_clearance(runs: list[RunAnalysis], path: Path) -> Path:
    """Swing-foot clearance of every swing over time."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(3.4, 2.6))
    for r in runs:
        for foot, mk in (("left", "o"), ("right", "s")):
            rows = [s for s in r.swings if s["foot"] == foot]
            ax.plot(
                [s["t_peak"] for s in rows],
                [100 * s["clearance"] for s in rows],
                mk,
                ms=3,
                label=f"{foot}: {_label(r)}",
            )
    ax.set(xlabel="time [s]", ylabel="swing clearance [cm]", title="Swing-foot clearance (FK, vs stance sole)")
    _legend_below(ax)
    return _save(fig, path)


def fig_gait(r: RunAnalysis, path: Path, window_s: float = 4.0) -> Path:
    """Foot heights with estimated stance (shaded) and simulator contact truth (bars), first ``window_s`` of walking."""
    plt = _plt()
    t = r.series["t"]
    t0 = t[np.argmax(~r.series["stance"].all(1))] if (~r.series["stance"].all(1)).any() else t[0]
    m = (t >= t0 - 0.2) & (t <= t0 + window_s)
    fig, axes = plt.subplots(2, 1, figsize=(6.8, 3.2), sharex=True)
    for k, (ax, foot) in enumerate(zip(axes, ("left", "right"), strict=True)):
        ax.plot(t[m], 100 * r.series["rel_height"][m, k], "k", lw=1, label="sole height over lower foot")
        ax.fill_between(
            t[m],
            0,
            1,
            where=r.series["stance"][m, k],
            transform=ax.get_xaxis_transform(),
            color="tab:blue",
            alpha=0.2,
            label="stance (estimated)",
        )
        if "contact_truth" in r.series:
            ax.fill_between(
                t[m],
                0,
                0.08,
                where=r.series["contact_truth"][m, k],
                transform=ax.get_xaxis_transform(),
                color="tab:red",
                alpha=0.6,
                label="contact (sim truth)",
            )
        ax.set(ylabel=f"{foot} [cm]")
    axes[0].legend(fontsize=5, loc="upper right")
    axes[1].set(xlabel="time [s]")
    fig.suptitle(f"Stance/swing segmentation: {r.summary['file']}", fontsize=8)
    return _save(fig, path)


def fig_eta(runs: list[RunAnalysis], path: Path) -> Path | None:
    """Decoded eta over time per run; ``None`` when no run has eta."""
    with_eta = [r for r in runs if "eta" in r.series]
    if not with_eta:
        return None
    plt = _plt()
    fig, ax = plt.subplots(figsize=(3.4, 2.6))
    for r in with_eta:
        eta = r.series["eta"]
        names = r.summary.get("eta_names") or ""
        for k in range(eta.shape[1]):
            ax.plot(r.series["t"], eta[:, k], lw=1, label=f"{_label(r)} eta[{k}] {names}")
    ax.set(xlabel="time [s]", ylabel="decoded $\\eta$", title="Student's decoded terrain parameters")
    _legend_below(ax)
    return _save(fig, path)


def _save(fig: Any, path: Path) -> Path:
    """Save and close a figure; the saved area grows to hold every label and legend (long run names)."""
    import matplotlib.pyplot as plt

    if fig.get_layout_engine() is None:
        fig.tight_layout()
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)
    return path


def write_figures(runs: list[RunAnalysis], out_dir: Path) -> list[Path]:
    """Write every figure into ``out_dir``; return the paths."""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = [
        fig_velocity_tracking(runs, out_dir / "fig_velocity_tracking.png"),
        fig_ankle_torque(runs, out_dir / "fig_ankle_pitch_torque.png"),
        fig_clearance(runs, out_dir / "fig_swing_clearance.png"),
    ]
    eta = fig_eta(runs, out_dir / "fig_eta.png")
    paths += [eta] if eta else []
    paths += [fig_gait(r, out_dir / f"fig_gait_{Path(r.summary['file']).stem}.png") for r in runs]
    return paths
