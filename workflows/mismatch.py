# SPDX-License-Identifier: Apache-2.0
"""Stage ``mismatch``: sim-vs-real mismatch discovery on one MCAP recording (issue 8).

Runs the ``gmloco-mismatch`` analysis (``gmloco.deploy.mismatch``) on ``mismatch.real`` (default: a committed sample
recording) with the simulated counterpart produced by replaying its commands in MuJoCo: contract checks,
localisation, attribution over the effect library, fit, held-out before/after. Writes ``report.json``,
``report.md``, ``config_patch.json`` and the plots. The smoke scale analyses the first seconds with a short horizon
and a subset of effects, which checks the machinery, not the verdict.

Run alone (works with plain ``python`` and ``PYTHONPATH=packages/*/src:workflows``)::

    python workflows/mismatch.py +exp=gm_loco run_dir=runs/gm_loco/<name> mismatch.real=data/logs/robot.mcap

Contract: ``run(cfg)`` reads ``cfg.mismatch``, writes every file under ``cfg.mismatch.out_dir`` and returns the
verdict and its numbers. A 9 s recording with the whole library costs about 50-60 s of CPU time (one core);
the analysis cannot stop midway, so ``max_minutes`` is not checked inside it. A worked example from the command
line to the report is in ``docs/mismatch.md``.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from omegaconf import DictConfig

if not __package__:  # run as ``python workflows/<name>.py``: the checkout root makes ``workflows`` importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workflows.pipeline_report import stage_bar

__all__ = ["main", "run"]


def _analysis_cfg(section: DictConfig, rate_hz: float = 500.0) -> Any:
    """Return the package's ``AnalysisCfg`` for the stage's section and a recording sampled at ``rate_hz``."""
    from gmloco.deploy.mismatch.pipeline import AnalysisCfg
    from gmloco.deploy.mismatch.replay import parse_ground, replay_cfg_for_rate

    try:
        ground, material = parse_ground(str(section.ground))
    except ValueError as exc:
        raise ValueError(f"mismatch.{exc}") from None
    horizon = None if section.horizon is None else int(section.horizon)
    replay = replay_cfg_for_rate(rate_hz, ground, material, horizon)
    cfg = AnalysisCfg(replay=replay, mirror_check=bool(section.mirror_check))
    cfg.attribution.effects = None if section.effects is None else tuple(str(e) for e in section.effects)
    cfg.attribution.n_boot = int(section.n_boot)
    return cfg


def _metrics(report: dict[str, Any]) -> dict[str, Any]:
    """The verdict, the winning effect and the report's headline numbers (an invalid input has fewer)."""
    mismatch = report.get("mismatch", {})
    metrics: dict[str, Any] = {"verdict": report["verdict"], "winner": report.get("winner") or "none"}
    metrics["untested_effects"] = float(len(report.get("untested", [])))
    for key in ("nominal_energy_ratio", "explained_fraction"):
        if isinstance(mismatch.get(key), int | float):
            metrics[key] = float(mismatch[key])
    if isinstance(report.get("runtime_s"), int | float):
        metrics["runtime_s"] = float(report["runtime_s"])
    return metrics


def run(cfg: DictConfig) -> dict[str, Any]:
    """Analyse ``mismatch.real`` and write the report; return the verdict and counts."""
    from gmloco.deploy.mismatch.io import read_recording
    from gmloco.deploy.mismatch.pipeline import analyze
    from gmloco.deploy.mismatch.report import write_report

    section = cfg.mismatch
    rec = read_recording(str(section.real))
    if section.duration_s is not None:
        rec = rec.slice(0, min(rec.n, round(float(section.duration_s) / rec.dt)))
    with stage_bar("mismatch fits", 1.0, "%") as update:
        result = analyze(rec, _analysis_cfg(section, 1.0 / rec.dt), lambda msg, frac: update(frac, f"mismatch: {msg}"))
    write_report(result, Path(section.out_dir), plots=bool(section.plots))
    return _metrics(result.report) | {"recording_s": float(rec.n * rec.dt)}


def main() -> None:
    """Command-line entry: run this stage alone in a run directory (Hydra)."""
    from workflows.hydra_entry import hydra_entry
    from workflows.pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra, only_stage="mismatch")


if __name__ == "__main__":
    main()
