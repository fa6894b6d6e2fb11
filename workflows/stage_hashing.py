# SPDX-License-Identifier: Apache-2.0
"""Per-stage config hashes, chained through upstream stages.

A stage is reused only when its own section, the common keys and all of its upstream stages' hashes are
unchanged.

Paths inside the run directory and the checkout are written relative (``${run_dir}``, ``${paths.root_dir}``)
before hashing, so a run directory copied to another machine (e.g. from the GPU machine) still resumes.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from omegaconf import DictConfig, OmegaConf

from workflows.run_dir import config_hash
from workflows.stage_registry import StageSpec

__all__ = ["PLACEMENT_KEYS", "VOLATILE_KEYS", "VOLATILE_STAGE_KEYS", "hashable_config", "stage_hashes"]

VOLATILE_KEYS = frozenset(
    {
        "run_dir",
        "run_name",
        "force",
        "max_minutes",
        "stages",
        "tracking",
        "paths",
        "device",
        "hydra",
        "sweep",
        "ablation",
    }
)
"""Top-level keys that never change a stage's result (where it runs, how long, how it is tracked)."""

VOLATILE_STAGE_KEYS = frozenset({"out_dir", "max_minutes", "resume", "fit_time_box", "device"})
"""Keys of a stage section that never change its result (``fit_time_box``: which walks one time box starts;
``device``: ``eval_mpm``'s copy of the pipeline's)."""

PLACEMENT_KEYS = {"train_teacher": frozenset({"gpus"}), "distill": frozenset({"gpus"})}
"""Keys of one stage's section that say where it runs, like the top-level ``device``: a training run resumes its
checkpoints on any number of GPUs."""


def _relocate(obj: Any, roots: Sequence[tuple[str, str]]) -> Any:
    """Replace absolute ``roots`` prefixes in every string of ``obj`` by their interpolation names."""
    if isinstance(obj, dict):
        return {k: _relocate(v, roots) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_relocate(v, roots) for v in obj]
    if isinstance(obj, str):
        for prefix, name in roots:
            obj = obj.replace(prefix, name)
    return obj


def hashable_config(cfg: DictConfig, stage_names: Sequence[str]) -> dict[str, Any]:
    """Return the resolved config without volatile keys and with run-dir / checkout paths made relative."""
    container = OmegaConf.to_container(cfg, resolve=True, enum_to_str=True)
    assert isinstance(container, dict)
    roots = [(str(cfg.run_dir), "${run_dir}"), (str(cfg.paths.root_dir), "${paths.root_dir}")]
    out: dict[str, Any] = {}
    for key, value in container.items():
        if key in VOLATILE_KEYS:
            continue
        if key in stage_names and isinstance(value, dict):
            skip = VOLATILE_STAGE_KEYS | PLACEMENT_KEYS.get(str(key), frozenset())
            value = {k: v for k, v in value.items() if k not in skip}
        out[str(key)] = _relocate(value, roots)
    return out


def stage_hashes(cfg: DictConfig, registry: Sequence[StageSpec]) -> dict[str, str]:
    """Hash each stage from the common keys, its own section and its upstream hashes (registry order)."""
    names = [s.name for s in registry]
    full = hashable_config(cfg, names)
    common = {k: v for k, v in full.items() if k not in names}
    hashes: dict[str, str] = {}
    for spec in registry:
        upstream = {u: hashes[u] for u in spec.needs}
        hashes[spec.name] = config_hash({"common": common, "stage": full.get(spec.name), "upstream": upstream})
    return hashes
