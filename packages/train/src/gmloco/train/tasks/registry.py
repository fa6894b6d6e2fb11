# SPDX-License-Identifier: Apache-2.0
"""Register the granular G1 tasks in mjlab's task registry (so mjlab's own train / play scripts run them).

Ids: ``Gmloco-Velocity-Granular-G1`` (3D-RFT, flat soft sand; the default), and
``Gmloco-Velocity-Granular-<Model>-<Terrain>-G1`` for Model in RFT3D, HeuristicRFT, ConeMulti, ConeSingle
and Terrain in Flat, Rough, Deep, plus ``Gmloco-Velocity-Rigid-Flat-G1``. Use from a shell as
``python -c "import gmloco.train.tasks.registry; from mjlab.scripts.train import main; main()" <task-id> ...``.
"""

from __future__ import annotations

from mjlab.tasks.registry import list_tasks, register_mjlab_task

from gmloco.train.config import ContactModelName, TerrainName
from gmloco.train.rl.runner import GmlocoOnPolicyRunner
from gmloco.train.tasks.g1_granular.env_cfgs import g1_granular_task, make_g1_granular_env_cfg
from gmloco.train.tasks.g1_granular.rl_cfg import make_g1_granular_ppo_cfg

__all__ = ["TASK_IDS", "register_gmloco_tasks", "task_id"]

_MODEL_NAMES: dict[ContactModelName, str] = {
    "rft3d": "RFT3D",
    "heuristic_rft": "HeuristicRFT",
    "cone_multi": "ConeMulti",
    "cone_single": "ConeSingle",
    "rft3d_calibrated": "RFT3DCalibrated",
}
_TERRAIN_NAMES: dict[TerrainName, str] = {"flat": "Flat", "rough": "Rough", "deep": "Deep"}


def task_id(contact_model: ContactModelName, terrain: TerrainName) -> str:
    """Return the registry id of a (contact model, terrain) pair."""
    if contact_model == "rigid":
        return f"Gmloco-Velocity-Rigid-{_TERRAIN_NAMES[terrain]}-G1"
    return f"Gmloco-Velocity-Granular-{_MODEL_NAMES[contact_model]}-{_TERRAIN_NAMES[terrain]}-G1"


def _variants() -> dict[str, tuple[ContactModelName, TerrainName]]:
    """All registered ids and their (contact model, terrain)."""
    out: dict[str, tuple[ContactModelName, TerrainName]] = {"Gmloco-Velocity-Granular-G1": ("rft3d", "flat")}
    for model in _MODEL_NAMES:
        for terrain in _TERRAIN_NAMES:
            out[task_id(model, terrain)] = (model, terrain)
    out[task_id("rigid", "flat")] = ("rigid", "flat")
    return out


TASK_IDS: tuple[str, ...] = tuple(_variants())
"""Every task id this module registers."""


def register_gmloco_tasks(num_envs: int = 4096) -> None:
    """Register every variant once (idempotent)."""
    known = set(list_tasks())
    for tid, (model, terrain) in _variants().items():
        if tid in known:
            continue
        register_mjlab_task(
            task_id=tid,
            env_cfg=make_g1_granular_env_cfg(g1_granular_task(model, terrain), num_envs),
            play_env_cfg=make_g1_granular_env_cfg(g1_granular_task(model, terrain, play=True), num_envs),
            rl_cfg=make_g1_granular_ppo_cfg(experiment_name=tid),
            runner_cls=GmlocoOnPolicyRunner,
        )


register_gmloco_tasks()
