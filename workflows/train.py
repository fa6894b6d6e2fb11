# SPDX-License-Identifier: Apache-2.0
"""Train a policy on the granular G1: the pipeline's train stage (``train_teacher``) alone (issue 4).

For the contact-model ablation (vanilla PPO), e.g.::

    python workflows/train.py +exp=ppo_rft3d                                   # runs/ppo_rft3d/<timestamp>
    python workflows/train.py +exp=ppo_rigid run_dir=runs/ppo_rigid/gpu max_minutes=9   # time-boxed, resumable

``+exp=gm_loco`` trains the VAE teacher the same way. The run directory, manifest, skip/resume, ``force``, time
box and exit codes are the pipeline's (``full_pipeline.py``); the stage itself is ``train_teacher.run``.
"""

from __future__ import annotations

import sys
from pathlib import Path

if not __package__:  # run as ``python workflows/<name>.py``: the checkout root makes ``workflows`` importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workflows.train_teacher import run

__all__ = ["main", "run"]


def main() -> None:
    """Command-line entry: run the train stage alone in a run directory (Hydra)."""
    from workflows.hydra_entry import hydra_entry
    from workflows.pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra, only_stage="train_teacher")


if __name__ == "__main__":
    main()
