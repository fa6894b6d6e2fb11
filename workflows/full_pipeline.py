# SPDX-License-Identifier: Apache-2.0
"""Run the whole pipeline: train_teacher -> distill -> export -> eval_mpm -> analyze_logs -> mismatch.

Usage:
    python workflows/full_pipeline.py +exp=gm_loco                  # full scale on a GPU, smoke scale on a CPU
    python workflows/full_pipeline.py +exp=gm_loco run_dir=runs/gm_loco/<name>   # resume: done stages skip
    python workflows/full_pipeline.py +exp=gm_loco force=[export]   # rerun one stage

A Python without the project's dependencies re-runs the command with the checkout's ``.venv`` (or says how to
make one): see ``project_python.py``.

Exit codes: 0 every stage done, skipped, blocked or not implemented yet; 1 a stage failed; 2 bad input;
3 a time box was reached (rerun the same command to continue).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

if not __package__:  # run as ``python workflows/<name>.py``: the checkout root makes ``workflows`` importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workflows.project_python import ensure_project_python

if TYPE_CHECKING:
    from omegaconf import DictConfig

__all__ = ["main", "run"]


def run(cfg: DictConfig) -> dict[str, Any]:
    """Run every stage selected by ``cfg.stages`` and return the summary (also in ``summary.json``)."""
    from workflows.pipeline_run import run_pipeline

    return run_pipeline(cfg)


def main() -> None:
    """Command-line entry (Hydra)."""
    ensure_project_python(__file__)
    from workflows.hydra_entry import hydra_entry
    from workflows.pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra)


if __name__ == "__main__":
    main()
