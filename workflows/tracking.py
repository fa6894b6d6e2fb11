# SPDX-License-Identifier: Apache-2.0
"""Pipeline-level tracking: TensorBoard always, wandb in the mode of ``tracking.wandb`` (``WANDB_MODE``)."""

from __future__ import annotations

import hashlib
import os
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

__all__ = ["Tracker"]


class Tracker:
    """Log each stage's numeric metrics and duration; heavy imports happen only when enabled."""

    def __init__(self, tracking: Any, run_dir: Path, run_name: str, config: Mapping[str, Any]) -> None:
        """Open the TensorBoard writer and, unless disabled, a wandb run that resumes with the run directory.

        Args:
            tracking: the ``tracking`` config node (``TrackingCfg``).
            run_dir: the run directory; TensorBoard writes to ``<run_dir>/tb``, wandb to ``<run_dir>/wandb``.
            run_name: display name of the run.
            config: resolved config, stored with the wandb run.
        """
        mode = str(getattr(tracking.wandb, "value", tracking.wandb))
        os.environ["WANDB_MODE"] = mode
        self._tb = _open_tensorboard(run_dir / "tb") if tracking.tensorboard else None
        self._wandb = None if mode == "disabled" else _open_wandb(tracking, run_dir, run_name, config)

    def log_stage(self, step: int, stage: str, metrics: Mapping[str, Any], duration_s: float) -> None:
        """Write ``<stage>/<metric>`` scalars and the stage's wall time at ``step`` (its pipeline index)."""
        scalars = {f"{stage}/{k}": float(v) for k, v in metrics.items() if _is_number(v)}
        scalars[f"pipeline/duration_s/{stage}"] = float(duration_s)
        if self._tb is not None:
            for key, value in scalars.items():
                self._tb.add_scalar(key, value, step)
            self._tb.flush()
        if self._wandb is not None:
            self._wandb.log(scalars)

    def close(self) -> None:
        """Flush and close both backends."""
        if self._tb is not None:
            self._tb.close()
        if self._wandb is not None:
            self._wandb.finish()


def _is_number(v: Any) -> bool:
    """Whether ``v`` is a real number (bools excluded)."""
    return isinstance(v, int | float) and not isinstance(v, bool)


def _open_tensorboard(log_dir: Path) -> Any:
    """Return a ``SummaryWriter``, or None with a warning when tensorboard is not installed."""
    try:
        from torch.utils.tensorboard import SummaryWriter
    except ImportError as e:
        warnings.warn(f"TensorBoard unavailable ({e}); pipeline scalars are only in summary.json", stacklevel=2)
        return None
    return SummaryWriter(log_dir=str(log_dir))


def _open_wandb(tracking: Any, run_dir: Path, run_name: str, config: Mapping[str, Any]) -> Any:
    """Start (or resume) a wandb run whose id is derived from the run directory; None if wandb is missing."""
    try:
        import wandb
    except ImportError:
        warnings.warn("wandb is not installed; tracking with TensorBoard only", stacklevel=2)
        return None
    run_id = hashlib.sha1(str(run_dir).encode()).hexdigest()[:12]
    return wandb.init(
        project=tracking.wandb_project,
        name=run_name,
        id=run_id,
        resume="allow",
        dir=str(run_dir),
        config=dict(config),
        settings=wandb.Settings(silent=True),
    )
