# SPDX-License-Identifier: Apache-2.0
"""Stage ``eval_mpm``: the exported policy walking on Newton implicit-MPM sand, scored by the paper's metrics (issue 9).

Thin wrapper around ``gmloco.eval.g1.run.run``: G1s (MuJoCo through Newton's ``SolverMuJoCo``) coupled two-way
with ``SolverImplicitMPM`` sand, the ONNX policy at 50 Hz over 200 Hz physics; ``robots_per_batch`` episodes at
once, each robot on its own sand window that moves with it (``moving_window=false``: a static bed covering the
course). Writes ``episodes.jsonl`` (one line per episode, the resume state), ``summary.json`` (temporary file +
``os.replace``), ``table_*.md/csv``, ``fig_*.png`` and ``recordings/*.mcap`` under ``cfg.eval_mpm.out_dir``;
returns success rate, velocity / yaw tracking error, DTW path error, support ratio and sinkage per
(terrain, scenario[, speed]) and ``all/...``, and ``throughput/episodes_per_minute``.

Run alone (time-boxed and resumable; works with plain ``python`` and ``PYTHONPATH=packages/*/src:workflows``)::

    python workflows/eval_mpm.py +exp=gm_loco run_dir=runs/gm_loco/<name> max_minutes=9
    python workflows/eval_mpm.py +exp=gm_loco run_dir=runs/gm_loco/<name> 'eval_mpm.gpus=[0,1,2,3]'   # four GPUs

The GPU machine's command line without Hydra: ``python -m gmloco.eval.g1.cli``; whether a cheaper MPM setting
walks as the accepted one does: ``python -m gmloco.eval.studies.convergence`` (``docs/mpm_eval.md``).
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from omegaconf import DictConfig

if not __package__:  # run as ``python workflows/<name>.py``: the checkout root makes ``workflows`` importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workflows.pipeline_report import say, stage_bar
from workflows.section_cfg import section_as
from workflows.stage_registry import StageIncompleteError

if TYPE_CHECKING:
    from gmloco.eval.g1.config import G1EvalCfg

__all__ = ["eval_cfg", "main", "run"]


def eval_cfg(cfg: DictConfig) -> G1EvalCfg:
    """The ``G1EvalCfg`` the pipeline's ``eval_mpm`` section holds (the section is one, plus the stage's fields).

    Its lists become the dataclass's tuples, and the device ``auto`` becomes Warp's default (CUDA when present).
    """
    from gmloco.eval.g1.config import G1EvalCfg

    auto = cfg.eval_mpm.device == "auto"
    return section_as(G1EvalCfg, cfg.eval_mpm, **({"device": None} if auto else {}))


def _episodes_logged(log: Path) -> int:
    """Complete lines of ``episodes.jsonl`` (one per finished episode); 0 before the file exists."""
    try:
        return log.read_bytes().count(b"\n")
    except OSError:
        return 0


@contextmanager
def _watch_episodes(log: Path, update: Callable[[float], None], period_s: float = 0.5) -> Iterator[None]:
    """Drive ``update`` with the episode count of ``log`` every ``period_s`` seconds while the block runs.

    The evaluation appends one line per finished episode (its resume state), so the file is the progress; reading
    it keeps the eval package free of console code.
    """
    stop = threading.Event()

    def poll() -> None:
        while not stop.wait(period_s):
            update(_episodes_logged(log))

    thread = threading.Thread(target=poll, name="eval_mpm-progress", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()


def run(cfg: DictConfig) -> dict[str, float]:
    """Evaluate ``<policy_dir>/<policy_file>`` on MPM sand; raise ``StageIncompleteError`` at the time box.

    With ``eval_mpm.gpus`` set, over those GPUs (one process each, every cell split into one share per GPU).
    """
    from gmloco.eval.g1.config import episode_specs
    from gmloco.eval.g1.gpus import run_on_gpus
    from gmloco.eval.g1.run import run as run_eval

    gpus = [str(g) for g in cfg.eval_mpm.get("gpus", [])]
    ecfg = eval_cfg(cfg)
    log = Path(ecfg.out_dir) / "episodes.jsonl"
    done = _episodes_logged(log) if ecfg.resume else 0
    if done:
        say(f"  eval_mpm: resumed from {log} ({done} episodes)")
    with (
        stage_bar("MPM episodes", len(episode_specs(ecfg)), "episodes") as update,
        _watch_episodes(log, update),
    ):
        metrics, complete = run_on_gpus(ecfg, gpus) if gpus else run_eval(ecfg)
    if not complete:
        raise StageIncompleteError(
            f"time box reached after {int(metrics.get('all/num_episodes', 0))} episodes; episodes.jsonl kept"
        )
    return metrics


def main() -> None:
    """Command-line entry: run this stage alone in a run directory (Hydra)."""
    from workflows.hydra_entry import hydra_entry
    from workflows.pipeline_run import run_from_hydra

    hydra_entry(run_from_hydra, only_stage="eval_mpm")


if __name__ == "__main__":
    main()
