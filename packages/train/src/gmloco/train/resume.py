# SPDX-License-Identifier: Apache-2.0
"""Checks before a run directory is resumed: same config as its checkpoints, and a checkpoint that loads.

``train_cfg.json`` records a run's config on its first call. A later call whose config differs in a key that shapes
the policy (:data:`RESUME_INVARIANT`) is refused, naming each differing leaf key, before anything is written: the
run directory's checkpoints stay another experiment's. A checkpoint that cannot be read (a kill mid-copy, a
truncated transfer) is named, renamed ``<name>.corrupt`` so no later call picks it, and the newest readable one
before it is used.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

__all__ = [
    "RESUME_INVARIANT",
    "ResumeError",
    "check_resume_cfg",
    "config_differences",
    "resumable_checkpoint",
]

RUN_CFG_FILE = "train_cfg.json"
"""Resolved run config written on the first call (compared on resume)."""
RESUME_INVARIANT = (
    "task",
    "jump",
    "num_envs",
    "num_steps_per_env",
    "hidden_dims",
    "seed",
    "history_length",
    "rsl_rl_overrides",
)
"""Top-level ``TrainRunCfg`` fields that must not change between the calls of one run (``rsl_rl_overrides`` holds the
algorithm: vanilla PPO, the VAE teacher or the student, with their network and loss settings)."""
_MISSING = object()


class ResumeError(ValueError):
    """A run directory that must not be resumed with this config, or whose checkpoints are all unreadable."""


def config_differences(saved: Any, current: Any, prefix: str = "", defaults: Any = _MISSING) -> list[str]:
    """Return ``"key: saved -> current"`` for every leaf where two JSON documents differ (dotted keys).

    ``defaults`` (the config's default values, same layout): a key the saved document lacks counts as unchanged
    while the current value is its default, so a field added to the config after a run started, left at the
    behaviour the run trained with, does not block the resume.
    """
    if isinstance(saved, Mapping) and isinstance(current, Mapping):
        out: list[str] = []
        sub = defaults if isinstance(defaults, Mapping) else {}
        for key in list(saved) + [k for k in current if k not in saved]:
            out += config_differences(
                saved.get(key, _MISSING), current.get(key, _MISSING), f"{prefix}{key}.", sub.get(key, _MISSING)
            )
        return out
    if saved == current or (saved is _MISSING and defaults is not _MISSING and current == defaults):
        return []
    show = lambda v: "absent" if v is _MISSING else json.dumps(v)  # noqa: E731
    return [f"{prefix.rstrip('.')}: {show(saved)} -> {show(current)}"]


def _experiment(cfg: Mapping[str, Any]) -> str:
    """The algorithm a run config trains: its actor class, or vanilla PPO."""
    actor = cfg.get("rsl_rl_overrides", {}).get("actor", {}).get("class_name")
    return str(actor).rsplit(":", 1)[-1] if actor else "vanilla PPO"


def check_resume_cfg(
    run_dir: Path, current: dict[str, Any], allowed: Iterable[str] = (), defaults: Mapping[str, Any] | None = None
) -> None:
    """Write ``current`` as the run config on the first call; refuse a later call that changes an invariant.

    Args:
        run_dir: The run directory.
        current: ``TrainRunCfg`` as JSON.
        allowed: Dotted keys (or key prefixes, e.g. ``task.reward_weights``) accepted as changed.
        defaults: The config's defaults as JSON: a key the saved config lacks is unchanged at its default.

    Raises:
        ResumeError: Naming each differing key, saved -> current, and what to do.
    """
    path = run_dir / RUN_CFG_FILE
    if path.exists():
        saved = json.loads(path.read_text())
        keep = tuple(allowed)
        changed = [
            d
            for k in RESUME_INVARIANT
            for d in config_differences(
                saved.get(k, _MISSING), current.get(k, _MISSING), f"{k}.", (defaults or {}).get(k, _MISSING)
            )
            if not any(d.split(":", 1)[0] == a or d.startswith(f"{a}.") for a in keep)
        ]
        if changed:
            old, new = _experiment(saved), _experiment(current)
            what = f"a {old} run; this config trains {new}" if old != new else f"a {old} run with another config"
            raise ResumeError(
                f"{run_dir} holds {what}. Resuming would mix the two in one policy. Differing keys (saved -> this "
                f"call): {'; '.join(changed)}. Use another run_dir for a new experiment, pass the run's own "
                "settings to resume it, or name the keys you mean to change in allow_changed."
            )
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(current, indent=1))
    os.replace(tmp, path)


def checkpoint_problem(path: Path) -> str | None:
    """Why ``path`` is no loadable rsl-rl checkpoint (unreadable, or no ``iter``); None when it is one."""
    import torch

    try:
        ckpt = torch.load(path, map_location="cpu", weights_only=False, mmap=True)
    except Exception as err:  # torch raises RuntimeError, EOFError, pickle errors... for a damaged file
        return f"{type(err).__name__}: {err}".splitlines()[0]
    if not isinstance(ckpt, dict) or "iter" not in ckpt:
        return "not an rsl-rl checkpoint (no 'iter' entry)"
    return None


def resumable_checkpoint(run_dir: Path) -> tuple[Path | None, list[str]]:
    """Return the newest readable ``model_<it>.pt`` and a line per unreadable newer one (renamed ``.corrupt``).

    Raises:
        ResumeError: If checkpoints exist but none can be read (resuming from scratch would discard the run).
    """
    from gmloco.train.rl.runner import CHECKPOINT_PATTERN

    found = sorted(
        ((int(m.group(1)), p) for p in run_dir.glob("model_*.pt") if (m := CHECKPOINT_PATTERN.match(p.name))),
        reverse=True,
    )
    skipped: list[str] = []
    for _, path in found:
        problem = checkpoint_problem(path)
        if problem is None:
            return path, skipped
        corrupt = path.with_name(f"{path.name}.corrupt")
        os.replace(path, corrupt)
        skipped.append(f"{path} is corrupt ({problem}); kept as {corrupt.name}")
    if skipped:
        raise ResumeError(
            f"every checkpoint in {run_dir} is unreadable: {'; '.join(skipped)}. Restore one (e.g. the committed "
            "artifacts/<run>/checkpoint.pt as model_<iteration>.pt) or use another run_dir to start afresh."
        )
    return None, skipped
