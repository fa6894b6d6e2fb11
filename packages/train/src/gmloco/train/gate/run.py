# SPDX-License-Identifier: Apache-2.0
"""``run_gate(GateCfg) -> dict``: resolve the policy, roll out every cell, summarise, write the JSON."""

from __future__ import annotations

import json
import os
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any

from gmloco.contact.extensions_io import load_rft_extensions
from gmloco.train.gate.config import GateCfg
from gmloco.train.gate.policy import gpu_minutes, read_policy
from gmloco.train.gate.rollout import gate_cells, run_cells
from gmloco.train.gate.summary import gate_metrics, gate_pass

__all__ = ["run_gate", "write_json"]


def write_json(path: str | Path, doc: dict[str, Any]) -> None:
    """Write ``doc`` to ``path`` through a temporary file and ``os.replace`` (never half a file)."""
    from gmloco.train.evaluation_ts import finite_json

    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.tmp")
    tmp.write_text(json.dumps(finite_json(doc), indent=1, default=str) + "\n")
    os.replace(tmp, out)


def _extensions(cfg: GateCfg) -> dict[str, Any] | None:
    """The fitted terms the ``rft3d_calibrated`` model ran with and their file; None for the other models."""
    if cfg.contact_model != "rft3d_calibrated":
        return None
    return {"file": cfg.rft_extensions_file, "values": asdict(load_rft_extensions(cfg.rft_extensions_file))}


def run_gate(cfg: GateCfg) -> dict[str, Any]:
    """Score ``cfg.policy_dir``; return (and with ``cfg.out_path`` write) the gate summary.

    Raises:
        GateInputError: If the run folder cannot be evaluated.
    """
    t0 = time.monotonic()
    policy = read_policy(cfg.policy_dir)
    cells = gate_cells(cfg)
    rows = run_cells(cfg, policy, cells)
    metrics = gate_metrics(cfg, rows)
    minutes = gpu_minutes(cfg.policy_dir)
    metrics["gpu_minutes"] = minutes["total"]
    summary: dict[str, Any] = {
        "policy": str(cfg.policy_dir),
        "actor": policy.kind,
        **metrics,
        "pass": gate_pass(metrics, cfg.thresholds, cfg.materials, cfg.parts),
        "thresholds": asdict(cfg.thresholds),
        "setup": {
            "episodes_per_cell": cfg.repeats,
            "episode_s": cfg.duration_s,
            "episodes": len(cells),
            "num_envs": cfg.num_envs,
            "device": cfg.device,
            "contact_model": cfg.contact_model,
            "rft_extensions": _extensions(cfg),
            "parts": list(cfg.parts),
            "yaw_command": policy.task.yaw_command,
            "heading_stiffness": policy.task.heading_stiffness,
            "gpu_minutes_by_run": minutes,
            "wall_s": time.monotonic() - t0,
            "cfg": json.loads(json.dumps(asdict(cfg), default=str)),
        },
    }
    if cfg.out_path is not None:
        write_json(cfg.out_path, summary)
    return summary
