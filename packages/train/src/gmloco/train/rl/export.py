# SPDX-License-Identifier: Apache-2.0
"""Export the actor to ONNX with deploy metadata: mjlab's keys plus gmloco's versioned document."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mjlab.rl.exporter_utils import attach_metadata_to_onnx, get_base_metadata

from gmloco.deploy.export import write_policy_metadata

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.rl import MjlabOnPolicyRunner

    from gmloco.train.config import GranularTaskCfg

__all__ = ["export_policy_onnx", "policy_metadata"]


def policy_metadata(env: ManagerBasedRlEnv, run_name: str, extra: dict[str, Any] | None = None) -> dict[str, Any]:
    """Return mjlab's deploy metadata plus action order, observation layout and timing (mjlab-style keys).

    mjlab's part: ``joint_names``, ``joint_stiffness`` / ``joint_damping`` (kp/kd), ``default_joint_pos``,
    ``action_scale``, ``observation_names`` and per-term scale / clip / history. Added here:
    ``action_joint_names`` (order of the 29 action entries), ``observation_dims`` (per-frame width of
    each actor term), ``observation_history_length``, ``observation_dim``, ``policy_dt`` / ``physics_dt`` [s]
    and anything in ``extra`` (contact model, terrain, ...). Tools that read mjlab exports use these keys; the
    complete description is gmloco's document (:func:`export_policy_onnx`).
    """
    meta: dict[str, Any] = get_base_metadata(env, run_name)
    om = env.observation_manager
    action_term = env.action_manager.get_term("joint_pos")
    term_dims = [math.prod(d) for d in om.group_obs_term_dim["actor"]]  # flat 1-D terms: history x width
    history = max(om.get_term_cfg("actor", om.active_terms["actor"][0]).history_length, 1)
    meta.update(
        {
            "action_joint_names": list(action_term.target_names),  # type: ignore[attr-defined]
            "observation_dims": [d // history for d in term_dims],
            "observation_history_length": history,
            "observation_dim": sum(term_dims),
            "policy_dt": env.step_dt,
            "physics_dt": env.physics_dt,
        }
    )
    meta.update(extra or {})
    return meta


def export_policy_onnx(
    runner: MjlabOnPolicyRunner,
    path: str | Path,
    task: GranularTaskCfg,
    run_name: str = "local",
    extra: dict[str, Any] | None = None,
    commit: str = "unknown",
) -> Path:
    """Export ``runner``'s actor (with its observation normalizer) to ``path`` and attach both metadata sets.

    The ONNX file carries mjlab's comma-joined keys (:func:`policy_metadata`) and the
    ``gmloco.deploy.export.PolicyMetadata`` document (input layout ``term_stacked``), which
    ``gmloco.deploy.export.OnnxPolicyRunner`` runs from. It is written next to ``path`` and moved into place with
    ``os.replace``; ``policy.json`` beside it holds the same document.

    Args:
        runner: Runner holding the trained actor.
        path: Output ``.onnx`` file.
        task: The training task config (recorded as trained on).
        run_name: Run identifier.
        extra: More mjlab-style keys.
        commit: Git commit of the training code.
    """
    from gmloco.train.tasks.g1_granular.policy_metadata import policy_metadata_from_env

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp_name = f".{path.name}.tmp"
    runner.export_policy_to_onnx(str(path.parent), tmp_name)
    env = runner.env.unwrapped
    attach_metadata_to_onnx(str(path.parent / tmp_name), policy_metadata(env, run_name, extra))
    om = env.observation_manager
    history = max(om.get_term_cfg("actor", om.active_terms["actor"][0]).history_length, 1)
    meta = policy_metadata_from_env(
        env, task, layout="term_stacked", history_length=history, policy_class="MLPModel", run_path=run_name,
        commit=commit,
    )  # fmt: skip
    write_policy_metadata(path.parent / tmp_name, meta)
    os.replace(path.parent / tmp_name, path)
    tmp_json = path.with_name(f".{path.stem}.json.tmp")
    tmp_json.write_text(json.dumps(meta.to_dict(), indent=1))
    os.replace(tmp_json, path.with_suffix(".json"))
    return path
