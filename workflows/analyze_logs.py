# SPDX-License-Identifier: Apache-2.0
"""Stage ``analyze_logs``: analysis of MCAP robot recordings (tracking, torques, clearance, decoded eta) (issue 7).

Run alone (time-boxed and resumable; works with plain ``python`` and ``PYTHONPATH=packages/*/src:workflows``)::

    python workflows/analyze_logs.py +exp=gm_loco run_dir=runs/gm_loco/<name> max_minutes=9

Contract for the implementation that replaces ``not_implemented`` below: ``run(cfg) -> dict[str, float]``
reads ``cfg.analyze_logs`` (plus ``cfg.seed`` and the resolved ``cfg.device``), writes every file under
``cfg.analyze_logs.out_dir`` (atomically: ``run_dir.atomic_write_*``), stops by ``cfg.analyze_logs.max_minutes`` by
saving resumable state and raising ``StageIncompleteError``, and returns its metrics. The runner adds
``metrics.json`` and the manifest entry.
"""

from __future__ import annotations

from stage_registry import not_implemented

__all__ = ["main", "run"]

run = not_implemented("analyze_logs")


def main() -> None:
    """Command-line entry: run this stage alone in a run directory (Hydra)."""
    from hydra_entry import hydra_entry
    from pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra, only_stage="analyze_logs")


if __name__ == "__main__":
    main()
