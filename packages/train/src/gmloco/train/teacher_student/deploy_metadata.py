# SPDX-License-Identifier: Apache-2.0
"""Map mjlab's export metadata onto the fields of ``gmloco.deploy.export.PolicyMetadata``.

mjlab's ``get_base_metadata(env, run_path)`` reads joints, PD gains, default pose, action scale and the ``actor``
group's term names, scales and clips from a live env. This turns that dict into ``PolicyMetadata`` keyword
arguments (plain data, so gmloco.train does not import gmloco.deploy):
``PolicyMetadata(**policy_metadata_kwargs(get_base_metadata(env, run), ...))``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

__all__ = ["policy_metadata_kwargs"]


def _clip_or_none(clip: Sequence[float]) -> list[float] | None:
    """Return ``[low, high]``, or None for mjlab's ``[-inf, inf]`` (no clip; JSON has no infinity)."""
    low, high = float(clip[0]), float(clip[1])
    return None if math.isinf(low) and math.isinf(high) else [low, high]


def policy_metadata_kwargs(
    base: Mapping[str, Any],
    *,
    observation_dims: Sequence[int],
    history_length: int,
    policy_dt: float,
    latent_dim: int,
    commit: str,
) -> dict[str, Any]:
    """Return ``PolicyMetadata`` keyword arguments from mjlab's base export metadata.

    Args:
        base: Output of ``mjlab.rl.exporter_utils.get_base_metadata(env, run_path)``.
        observation_dims: Size of each ``actor`` term, in ``base["observation_names"]`` order
            (e.g. ``env.observation_manager.group_obs_term_dim["actor"]``, flattened).
        history_length: N of the student's history input.
        policy_dt: Policy period [s] (``env.step_dt``).
        latent_dim: Student latent size.
        commit: Git commit of the training code.

    Raises:
        ValueError: If ``observation_dims`` does not have one entry per observation term.
    """
    names = list(base["observation_names"])
    if len(observation_dims) != len(names):
        raise ValueError(f"{len(observation_dims)} observation dims for {len(names)} terms {names}.")
    joints = list(base["joint_names"])
    scale = base["action_scale"]
    action_scale = [float(s) for s in scale] if isinstance(scale, Sequence) else [float(scale)] * len(joints)
    return {
        "joint_names": joints,
        "joint_stiffness": [float(k) for k in base["joint_stiffness"]],
        "joint_damping": [float(d) for d in base["joint_damping"]],
        "default_joint_pos": [float(q) for q in base["default_joint_pos"]],
        "action_scale": action_scale,
        "observation_names": names,
        "observation_dims": [int(d) for d in observation_dims],
        "observation_scale": list(base["observation_terms_scale"]),
        "observation_clip": [_clip_or_none(c) for c in base["observation_terms_clip"]],
        "history_length": history_length,
        "policy_dt": policy_dt,
        "latent_dim": latent_dim,
        "commit": commit,
        "run_path": str(base.get("run_path", "local")),
    }
