# SPDX-License-Identifier: Apache-2.0
"""Several workers on one study: the study's signature, the trials they claim, one worker process per GPU.

Every worker runs the same command; the first stores the study's signature (objective, direction, search space)
as a study attribute, and a worker whose config differs is refused (exit code 2) instead of mixing two searches in
one study. With ``sweep.gpus=[0,1,...]`` one command starts one worker process per GPU (``device=cuda:<i>``), so
each GPU trains one trial at a time.
"""

from __future__ import annotations

import copy
import json
from collections.abc import Callable, Sequence
from typing import Any

from omegaconf import DictConfig

from workflows.stage_runner import PipelineConfigError

__all__ = ["SIGNATURE_ATTR", "check_signature", "claimed_trials", "gpu_worker_cfgs", "run_gpu_workers", "signature"]

SIGNATURE_ATTR = "gmloco_sweep_signature"
"""Study user attribute holding the signature of the search that created it."""


def signature(metric: str, direction: str, distributions: dict[str, Any]) -> dict[str, Any]:
    """The search a study holds: objective, direction and each parameter's Optuna distribution (JSON)."""
    from optuna.distributions import distribution_to_json

    params = {k: json.loads(distribution_to_json(d)) for k, d in sorted(distributions.items())}
    return {"metric": str(metric), "direction": str(direction), "params": params}


def _differences(stored: dict[str, Any], wanted: dict[str, Any]) -> list[str]:
    """What differs between two signatures, one short clause each."""
    found = [f"{k} '{stored.get(k)}' vs '{wanted[k]}'" for k in ("metric", "direction") if stored.get(k) != wanted[k]]
    old, new = stored.get("params", {}), wanted["params"]
    found += [f"'{k}' only in the study" for k in sorted(set(old) - set(new))]
    found += [f"'{k}' only in this config" for k in sorted(set(new) - set(old))]
    found += [
        f"'{k}' {old[k]['attributes']} vs {new[k]['attributes']}"
        for k in sorted(set(old) & set(new))
        if old[k] != new[k]
    ]
    return found


def check_signature(study: Any, wanted: dict[str, Any], where: str) -> None:
    """Store ``wanted`` on a study that has none; raise (exit code 2) when the study holds another search."""
    from sqlalchemy.exc import IntegrityError

    stored = study.user_attrs.get(SIGNATURE_ATTR)
    if stored is None:
        try:
            study.set_user_attr(SIGNATURE_ATTR, wanted)
            return
        except IntegrityError:  # another worker stored it between the read and the write: compare with that one
            stored = study.user_attrs.get(SIGNATURE_ATTR, wanted)
    if diff := _differences(stored, wanted):
        raise PipelineConfigError(
            "sweep.params",
            f"sweep.params: study '{study.study_name}' in {where} holds a different search ({'; '.join(diff)}). "
            "Start every worker with the same sweep config, or name another study with sweep.study_name=<name>.",
        )


def claimed_trials(study: Any, finished: Sequence[Any]) -> int:
    """Trials finished plus those running now (in this or another worker): what a worker counts to stop."""
    from optuna.trial import TrialState

    return len(finished) + len(study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)))


def gpu_worker_cfgs(cfg: DictConfig) -> list[DictConfig]:
    """One config per GPU of ``sweep.gpus``: ``device=cuda:<i>``, one GPU each, training on that GPU alone."""
    out = []
    for gpu in [int(g) for g in cfg.sweep.gpus]:
        wcfg = copy.deepcopy(cfg)
        wcfg.device, wcfg.sweep.gpus, wcfg.train_teacher.gpus = f"cuda:{gpu}", [gpu], []
        out.append(wcfg)
    return out


def run_gpu_workers(cfgs: Sequence[DictConfig], work: Callable[[DictConfig], int]) -> list[int]:
    """Run ``work(cfg)`` in one spawned process per config; return their exit codes (in order)."""
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")  # CUDA cannot be used in a forked child
    procs = [ctx.Process(target=_work_and_exit, args=(work, c), name=f"sweep-{c.device}") for c in cfgs]
    for p in procs:
        p.start()
    for p in procs:
        p.join()
    return [int(p.exitcode if p.exitcode is not None else 1) for p in procs]


def _work_and_exit(work: Callable[[DictConfig], int], cfg: DictConfig) -> None:
    """Process body: run the worker, exit with its code."""
    raise SystemExit(work(cfg))
