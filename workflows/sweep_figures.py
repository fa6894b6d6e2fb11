# SPDX-License-Identifier: Apache-2.0
"""Optuna's own figures of a study (``optuna.visualization.matplotlib``), written beside ``figures/sweep.png``."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

__all__ = ["write_optuna_figures"]


def _save(ax: Any, path: Path) -> str:
    """Save the figure holding ``ax`` (an Axes or an array of them) to ``path``; return its file name."""
    import matplotlib.pyplot as plt

    fig = getattr(ax, "figure", None) or ax.flat[0].figure
    fig.set_size_inches(7.0, 4.5)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path.name


def write_optuna_figures(study: Any, folder: Path, with_importances: bool) -> list[str]:
    """Write ``optimization_history.png`` and (``with_importances``) ``param_importances.png``; return the names.

    Importances use PED-ANOVA, as ``study_summary.json`` does (Optuna's default fANOVA needs scikit-learn).
    """
    import matplotlib

    matplotlib.use("Agg")
    import optuna
    from optuna.visualization import matplotlib as ovm

    names = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
        names.append(_save(ovm.plot_optimization_history(study), folder / "optimization_history.png"))
        if with_importances:
            evaluator = optuna.importance.PedAnovaImportanceEvaluator()
            names.append(
                _save(ovm.plot_param_importances(study, evaluator=evaluator), folder / "param_importances.png")
            )
    return names
