# SPDX-License-Identifier: Apache-2.0
"""Stage ``analyze_logs``: analysis of MCAP robot recordings (tracking, torques, clearance, decoded eta) (issue 7).

Runs ``gmloco.deploy.logs.analyze`` (the ``gmloco-logs`` command) on ``analyze_logs.inputs`` (files or folders;
default: the committed sample recordings) plus, with ``analyze_logs.include_run_recordings``, every ``*.mcap`` an
earlier stage wrote under the run directory. Writes ``summary.md``, ``summary.csv``, ``tracking.csv``,
``summary.json`` and ``figures/``; a recording that cannot be read is listed under "Files not analyzed".

Run alone (works with plain ``python`` and ``PYTHONPATH=packages/*/src:workflows``)::

    python workflows/analyze_logs.py +exp=gm_loco run_dir=runs/gm_loco/<name> 'analyze_logs.inputs=[data/logs]'

Contract: ``run(cfg)`` reads ``cfg.analyze_logs``, writes every file under ``cfg.analyze_logs.out_dir`` and returns
counts and the mean velocity-tracking error; it takes seconds per recording, so it has no time box of its own.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

from omegaconf import DictConfig

if not __package__:  # run as ``python workflows/<name>.py``: the checkout root makes ``workflows`` importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workflows.run_dir import atomic_write_json

__all__ = ["main", "recordings", "run"]


def recordings(cfg: DictConfig) -> list[str | Path]:
    """Return the configured inputs, then the ``*.mcap`` files under the run directory (outside this stage)."""
    section = cfg.analyze_logs
    inputs: list[str | Path] = [str(p) for p in section.inputs]
    if section.include_run_recordings:
        out = Path(section.out_dir).resolve()
        found = sorted(p for p in Path(cfg.run_dir).rglob("*.mcap") if out not in p.resolve().parents)
        inputs += found
    return inputs


def _metrics(content: dict[str, Any]) -> dict[str, float]:
    """Counts of the analysis and the mean tracking RMSE over commanded-speed segments (NaN-free)."""
    rmse = [float(t["rmse"]) for t in content["tracking"] if math.isfinite(float(t["rmse"]))]
    metrics = {
        "recordings": float(len(content["runs"])),
        "failed_recordings": float(len(content["failures"])),
        "figures": float(len(content["figures"])),
        "tracking_segments": float(len(content["tracking"])),
    }
    if rmse:
        metrics["tracking_rmse_mean"] = sum(rmse) / len(rmse)
    return metrics


def run(cfg: DictConfig) -> dict[str, float]:
    """Analyze the recordings; fail when none could be read."""
    from gmloco.deploy.logs.analysis.report import analyze

    section = cfg.analyze_logs
    inputs = recordings(cfg)
    content = analyze(inputs, section.out_dir, figures=bool(section.figures), progress=False)
    atomic_write_json(Path(section.out_dir) / "inputs.json", {"inputs": [str(p) for p in inputs]})
    if not content["runs"]:
        raise RuntimeError(f"no recording could be analyzed among {inputs}: {content['failures']}")
    return _metrics(content)


def main() -> None:
    """Command-line entry: run this stage alone in a run directory (Hydra)."""
    from workflows.hydra_entry import hydra_entry
    from workflows.pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra, only_stage="analyze_logs")


if __name__ == "__main__":
    main()
