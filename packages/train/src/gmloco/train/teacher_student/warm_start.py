# SPDX-License-Identifier: Apache-2.0
"""Start a VAE teacher from a trained vanilla-PPO policy of the same task.

The PPO baselines see a stack of H actor frames (mjlab term-major layout: for each term, its H frames oldest first);
the teacher's actor sees one frame o_t and the latent z_t. The map below makes the teacher's initial actor equal to
the PPO actor whenever the H stacked frames are equal (a stationary history), with the latent's input columns set to
zero, so the teacher starts from a walking gait and PPO then learns to use z. Encoder and decoder keep their fresh
initialisation; the critic (same privileged group) is copied when its shapes match.

For frame column j of term block (offset o, width d) PPO's column of frame k is ``H·o + k·d + (j - o)``. With PPO
normalizer statistics (m_k, s_k = std_k + eps) and the teacher normalizer set to the newest frame's (m, s):
``Σ_k W_k (x - m_k)/s_k = (Σ_k W_k s/s_k)(x - m)/s + Σ_k W_k (m - m_k)/s_k``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import torch

from gmloco.train.teacher_student.checkpoint_teacher import TEACHER_SOURCE_KEY

__all__ = [
    "STUDENT_ENCODER_PREFIXES",
    "stacked_columns",
    "student_encoder_from",
    "teacher_actor_from_ppo",
    "warm_start_from_ppo",
]

_NORM = "obs_normalizer."
_FIRST = "mlp.0."


def stacked_columns(term_dims: Sequence[int], frames: int) -> torch.Tensor:
    """Return ``[frames, sum(term_dims)]``: PPO input column of each (frame, single-frame column), oldest first."""
    cols = torch.empty(frames, sum(term_dims), dtype=torch.long)
    offset = 0
    for d in term_dims:
        for k in range(frames):
            cols[k, offset : offset + d] = frames * offset + k * d + torch.arange(d)
        offset += d
    return cols


def teacher_actor_from_ppo(
    ppo: dict[str, torch.Tensor],
    teacher: dict[str, torch.Tensor],
    term_dims: Sequence[int],
    eps: float = 1e-2,
) -> dict[str, torch.Tensor]:
    """Return a teacher actor state dict whose MLP reproduces the PPO actor on a stationary frame stack.

    Args:
        ppo: The PPO actor state dict (``obs_normalizer.*``, ``mlp.*``, ``distribution.*``) over H stacked frames.
        teacher: The teacher actor's current state dict (gives shapes; its encoder and decoder are kept).
        term_dims: Width of each actor term in one frame, in order (G1: 3, 3, 3, 29, 29, 29).
        eps: The normalizers' epsilon (rsl-rl ``EmpiricalNormalization``: 1e-2).

    Raises:
        ValueError: If the PPO input is not a whole number of frames, or a hidden layer's shape differs.
    """
    frame = sum(term_dims)
    w, b = ppo[_FIRST + "weight"], ppo[_FIRST + "bias"]
    if w.shape[1] % frame:
        raise ValueError(f"PPO actor input {w.shape[1]} is not a stack of {frame}-wide frames (term_dims {term_dims})")
    frames = w.shape[1] // frame
    latent = teacher[_FIRST + "weight"].shape[1] - frame
    if latent < 0 or teacher[_FIRST + "weight"].shape[0] != w.shape[0]:
        raise ValueError(f"teacher first layer {tuple(teacher[_FIRST + 'weight'].shape)} does not fit {tuple(w.shape)}")
    cols = stacked_columns(term_dims, frames)
    mean, std = ppo[_NORM + "_mean"][0], ppo[_NORM + "_std"][0] + eps
    newest = cols[-1]
    m, s = mean[newest], std[newest]
    w_eff = torch.zeros(w.shape[0], frame, dtype=w.dtype)
    b_eff = b.clone()
    for k in range(frames):
        wk, sk = w[:, cols[k]], std[cols[k]]
        w_eff += wk * (s / sk)
        b_eff += wk @ ((m - mean[cols[k]]) / sk)
    out = {key: value.clone() for key, value in teacher.items()}
    out[_NORM + "_mean"] = m.unsqueeze(0).clone()
    out[_NORM + "_var"] = ppo[_NORM + "_var"][0][newest].unsqueeze(0).clone()
    out[_NORM + "_std"] = ppo[_NORM + "_std"][0][newest].unsqueeze(0).clone()
    out[_NORM + "count"] = ppo[_NORM + "count"].clone()
    out[_FIRST + "weight"] = torch.cat([w_eff, torch.zeros(w.shape[0], latent, dtype=w.dtype)], dim=1)
    out[_FIRST + "bias"] = b_eff
    for key, value in ppo.items():
        if key.startswith((_NORM, _FIRST)):
            continue
        if key not in out or out[key].shape != value.shape:
            raise ValueError(f"PPO actor entry {key} {tuple(value.shape)} has no match in the teacher actor")
        out[key] = value.clone()
    return out


def warm_start_from_ppo(alg: Any, path: str | Path, term_dims: Sequence[int]) -> dict[str, Any]:
    """Load a PPO checkpoint's actor (mapped) and critic (if shapes match) into a ``TeacherPPO``; return a record.

    Args:
        alg: The runner's ``TeacherPPO`` (its ``_raw_actor`` / ``_raw_critic`` or ``actor`` / ``critic``).
        path: The PPO checkpoint (``actor_state_dict``, ``critic_state_dict``).
        term_dims: Width of each actor term in one frame.
    """
    ckpt = torch.load(path, map_location="cpu", weights_only=False)
    actor = getattr(alg, "_raw_actor", None) or alg.actor
    critic = getattr(alg, "_raw_critic", None) or alg.critic
    device = next(actor.parameters()).device
    mapped = teacher_actor_from_ppo(
        ckpt["actor_state_dict"], {k: v.cpu() for k, v in actor.state_dict().items()}, term_dims
    )
    actor.load_state_dict({k: v.to(device) for k, v in mapped.items()}, strict=True)
    own = critic.state_dict()
    theirs = ckpt["critic_state_dict"]
    critic_copied = own.keys() == theirs.keys() and all(own[k].shape == theirs[k].shape for k in own)
    if critic_copied:
        critic.load_state_dict({k: v.to(device) for k, v in theirs.items()}, strict=True)
    return {"warm_start_ppo": str(path), "ppo_iteration": int(ckpt.get("iter", -1)), "critic_copied": critic_copied}


STUDENT_ENCODER_PREFIXES = ("encoder.", "history_normalizer.")
"""Student actor entries that map the proprioceptive history to z_hat (TCN and its input normalizer)."""


def student_encoder_from(alg: Any, path: str | Path) -> dict[str, Any]:
    """Copy an earlier student's history encoder (TCN + history normalizer) into a ``StudentPPO``; return a record.

    Used when a student is distilled from a new teacher: the actor MLP, action distribution and critic come from the
    new teacher (``init_from_teacher``), the encoder that infers the terrain latent from proprioception starts from
    the earlier student instead of from scratch. The new teacher's latent space may differ from the old one's; the
    latent loss ``||z - z_hat||^2`` then moves the encoder, which only needs to adapt, not learn from nothing.

    Args:
        alg: The runner's ``StudentPPO`` (its ``_raw_actor`` or ``actor``).
        path: A student checkpoint (``actor_state_dict`` with ``encoder.*`` and ``history_normalizer.*``), with its
            teacher embedded or detached (``checkpoint_teacher``); the teacher itself is not read.

    Raises:
        ValueError: If ``path`` holds no student encoder, or its shapes differ (another history length or latent
            size).
    """
    ckpt = torch.load(path, map_location="cpu", weights_only=False)
    theirs = {k: v for k, v in ckpt.get("actor_state_dict", {}).items() if k.startswith(STUDENT_ENCODER_PREFIXES)}
    if not theirs or ("teacher_state_dict" not in ckpt and TEACHER_SOURCE_KEY not in ckpt):
        raise ValueError(f"{path} is not a student checkpoint (no encoder.* entries / no teacher): pass a student's")
    actor = getattr(alg, "_raw_actor", None) or alg.actor
    own = actor.state_dict()
    mine = {k for k in own if k.startswith(STUDENT_ENCODER_PREFIXES)}
    if mine != theirs.keys() or any(own[k].shape != theirs[k].shape for k in mine):
        diff = sorted(
            k for k in mine | theirs.keys() if k not in own or k not in theirs or own[k].shape != theirs[k].shape
        )
        raise ValueError(f"student encoder of {path} does not fit this student (history length / latent size?): {diff}")
    device = next(actor.parameters()).device
    own.update({k: v.to(device) for k, v in theirs.items()})
    actor.load_state_dict(own, strict=True)
    return {
        "warm_start_student_encoder": str(path),
        "student_iteration": int(ckpt.get("iter", -1)),
        "entries": len(theirs),
    }
