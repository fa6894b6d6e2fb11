# SPDX-License-Identifier: Apache-2.0
"""Refuse a command that would replace results in an existing run directory without ``force`` naming them.

A run directory belongs to one experiment (``manifest.json`` records ``exp_name``; runs made before it was recorded
are known by their ``config.yaml``). A stage whose recorded config differs from the command's, and whose folder
holds results, is rerun only when ``force`` names it or a stage it depends on (its results are then stale anyway).
Both checks run before Hydra or a stage writes anything.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from workflows.manifest import Manifest
from workflows.run_dir import RunDir, list_outputs
from workflows.stage_hashing import stage_hashes
from workflows.stage_registry import StageSpec
from workflows.stage_runner import forced_stages

__all__ = ["recorded_experiment", "run_dir_problem"]

_NOT_RESULTS = frozenset({"error.log"})
"""Files of a stage folder that are no results (a failed attempt's traceback)."""


def recorded_experiment(layout: RunDir, manifest: Manifest) -> str:
    """The experiment a run directory belongs to ('' for a new one)."""
    if manifest.exp_name:
        return manifest.exp_name
    if layout.config_yaml.is_file():
        old = OmegaConf.load(layout.config_yaml)
        return str(old.get("exp_name", "") or "") if isinstance(old, DictConfig) else ""
    return ""


def _rerun_allowed(registry: Sequence[StageSpec], forced: set[str]) -> set[str]:
    """Stages that ``force`` names, and every stage downstream of one (registry order)."""
    allowed = set(forced)
    for spec in registry:
        if allowed & set(spec.needs):
            allowed.add(spec.name)
    return allowed


def _force_value(cfg: DictConfig) -> object:
    """``cfg.force`` as a plain Python value."""
    return OmegaConf.to_object(cfg.force) if OmegaConf.is_config(cfg.force) else cfg.force


def run_dir_problem(cfg: DictConfig, registry: Sequence[StageSpec]) -> tuple[str, str] | None:
    """Why this command must not run in ``cfg.run_dir``, as ``(key, message)``; None when it may."""
    layout = RunDir(Path(str(cfg.run_dir)).resolve())
    if not layout.manifest_json.is_file() and not layout.config_yaml.is_file():
        return None
    manifest = Manifest.load(layout.manifest_json)
    exp = recorded_experiment(layout, manifest)
    if exp and exp != str(cfg.exp_name):
        return "run_dir", (
            f"run_dir {layout.root} holds a '{exp}' run; +exp={cfg.exp_name} would write into it and replace its "
            f"results. Leave run_dir out (a new run goes to runs/{cfg.exp_name}/<time>), choose a new run_dir, "
            f"or resume the run with +exp={exp}."
        )
    hashes = stage_hashes(cfg, registry)
    allowed = _rerun_allowed(registry, forced_stages(_force_value(cfg), registry))
    for spec in registry:
        rec = manifest.stages.get(spec.name)
        if spec.name not in cfg.stages or rec is None or rec.config_hash == hashes[spec.name]:
            continue
        out_dir = str(cfg[spec.name].out_dir)
        results = [f for f in list_outputs(out_dir) if f not in _NOT_RESULTS]
        if results and spec.name not in allowed:
            return "force", (
                f"stage '{spec.name}' in run_dir {layout.root} holds {len(results)} result files made with another "
                f"config than this command's (a setting of the stage, of a stage it needs, or the seed changed), and "
                f"running it would replace them. Add force=[{spec.name}] to replace them, or choose a new run_dir "
                "to keep them."
            )
    return None
