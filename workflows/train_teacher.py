# SPDX-License-Identifier: Apache-2.0
"""Stage ``train_teacher``: PPO teacher with a VAE terrain encoder on mjlab with a granular contact model (issues 4, 6).

Run alone (time-boxed and resumable; works with plain ``python`` and ``PYTHONPATH=packages/*/src:workflows``)::

    python workflows/train_teacher.py +exp=gm_loco run_dir=runs/gm_loco/<name> max_minutes=9

Contract for the implementation that replaces ``not_implemented`` below: ``run(cfg) -> dict[str, float]``
reads ``cfg.train_teacher`` (plus ``cfg.seed`` and the resolved ``cfg.device``), writes every file under
``cfg.train_teacher.out_dir`` (atomically: ``run_dir.atomic_write_*``), stops by ``cfg.train_teacher.max_minutes`` by
saving resumable state and raising ``StageIncompleteError``, and returns its metrics. The runner adds
``metrics.json`` and the manifest entry.
"""

from __future__ import annotations

from stage_registry import not_implemented

__all__ = ["main", "run"]

run = not_implemented("train_teacher")


def main() -> None:
    """Command-line entry: run this stage alone in a run directory (Hydra)."""
    from hydra_entry import hydra_entry
    from pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra, only_stage="train_teacher")


if __name__ == "__main__":
    main()
