# SPDX-License-Identifier: Apache-2.0
"""Localisation: which signal, joint, gait phase and time window differ beyond the noise floor.

Cells are (signal, joint or axis, phase of the joint's own foot; left foot for trunk/arm/IMU channels; for a held
pelvis, the joint's own motion label and the busiest joint's for IMU channels, ``segmentation.motion_phases``). A cell's
statistic is its mean normalised residual energy (1 at the floor); its p-value treats
``energy * n_eff_cell`` as chi-square with ``n_eff_cell`` degrees of freedom, where ``n_eff_cell`` scales the
cell's sample count by the recording's ``n_eff / n``. Benjamini-Hochberg controls the false-discovery rate
across cells (``shared/reference/mismatch-discovery.md`` section 3.2 step 5).
"""

from __future__ import annotations

import numpy as np

from gmloco.deploy.mismatch.segmentation import PHASES

__all__ = ["bh_qvalues", "localize"]


def bh_qvalues(p: np.ndarray) -> np.ndarray:
    """Benjamini-Hochberg q-values of p-values, same shape."""
    p = np.asarray(p, float)
    order = np.argsort(p)
    ranked = p[order] * len(p) / np.arange(1, len(p) + 1)
    q = np.minimum.accumulate(ranked[::-1])[::-1]
    out = np.empty_like(q)
    out[order] = np.clip(q, 0, 1)
    return out


def _foot_of_channel(names: list[str]) -> np.ndarray:
    """Foot index whose phase labels a channel (0 left, 1 right)."""
    return np.array([1 if ":right_" in n and ("hip" in n or "knee" in n or "ankle" in n) else 0 for n in names])


def localize(
    r: np.ndarray,
    names: list[str],
    phases: np.ndarray,
    times: np.ndarray,
    n_ratio: float,
    window_s: float = 1.0,
    q_max: float = 0.01,
    min_ratio: float = 1.5,
    labels: tuple[str, ...] = PHASES,
    columns: np.ndarray | None = None,
) -> dict:
    """Return flagged cells and time windows plus the full signal x phase energy table.

    Args:
        r: Normalised residuals, shape [S, P, C].
        names: Channel names ``signal:joint``, length C.
        phases: Phase codes (indices into ``labels``) at the compare points, shape [S, P, K].
        times: Compare-point times [s], shape [S, P].
        n_ratio: ``n_eff / n`` of the recording.
        window_s: Time-window length [s].
        q_max: Largest FDR q-value of a flagged cell or window.
        min_ratio: Smallest energy ratio of a flagged cell or window.
        labels: Phase names; the foot phases :data:`PHASES` by default.
        columns: Column of ``phases`` that labels each channel, shape [C]; by default the channel's foot
            (0 left, 1 right).
        q_max: FDR level.
        min_ratio: Smallest energy ratio reported as a mismatch.
    """
    from scipy.stats import chi2

    foot = _foot_of_channel(names) if columns is None else columns
    cells, table = [], {}
    for c, name in enumerate(names):
        ph = phases[:, :, foot[c]]
        for k, pname in enumerate(labels):
            m = ph == k
            if m.sum() < 5:
                continue
            e = float(np.mean(r[:, :, c][m] ** 2))
            dof = max(1.0, m.sum() * n_ratio)
            table[(name, pname)] = e
            cells.append((name, pname, e, float(chi2.sf(e * dof, dof)), int(m.sum())))
    q = bh_qvalues(np.array([c[3] for c in cells])) if cells else np.array([])
    flagged = [
        {
            "signal": n.split(":")[0],
            "joint": n.split(":")[1],
            "phase": p,
            "energy_ratio": round(e, 3),
            "q_fdr": float(qq),
            "n": cnt,
        }
        for (n, p, e, _, cnt), qq in zip(cells, q, strict=True)
        if qq < q_max and e >= min_ratio
    ]
    flagged.sort(key=lambda c: -c["energy_ratio"])
    wins = []
    t0 = times.min()
    wid = ((times - t0) // window_s).astype(int)
    groups = sorted({n.split(":")[0] for n in names})
    for w in np.unique(wid):
        m = wid == w
        for g in groups:
            cols = [i for i, n in enumerate(names) if n.startswith(g + ":")]
            e = float(np.mean(r[:, :, cols][m] ** 2))
            dof = max(1.0, m.sum() * len(cols) * n_ratio)
            wins.append((g, float(t0 + w * window_s), e, float(chi2.sf(e * dof, dof))))
    qw = bh_qvalues(np.array([w[3] for w in wins])) if wins else np.array([])
    windows = [
        {"signal": g, "t": [round(t, 3), round(t + window_s, 3)], "energy_ratio": round(e, 3), "q_fdr": float(qq)}
        for (g, t, e, _), qq in zip(wins, qw, strict=True)
        if qq < q_max and e >= min_ratio
    ]
    return {"cells": flagged[:50], "windows": windows, "table": table}
