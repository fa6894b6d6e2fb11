# SPDX-License-Identifier: Apache-2.0
"""Rewrite a version-1 student ONNX's metadata as the versioned document, from facts beside it.

``python -m gmloco.train.tasks.g1_granular.upgrade_metadata <policy_dir> [--set key=value ...]`` reads the
policy's ``train_cfg.json`` (the training task) and the file's version-1 entries (joints, kp/kd, default pose,
action scale, term widths, history length, latent size, commit and run, all read from the live env at export),
adds the G1 effort limits and everything the task determines, then rewrites ``policy.onnx`` (atomically, the
version-1 entries removed) and ``policy.json``. A task field missing from ``train_cfg.json`` is refused unless
``--set`` gives it (e.g. ``foot_faces=sole`` or ``yaw_command=heading_envs`` for runs trained before that field
existed; a value is read as JSON where it parses, else as a string). Exit 2 on bad input.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Mapping, Sequence
from dataclasses import fields
from pathlib import Path
from typing import Any

import onnx

from gmloco.train.config import GranularTaskCfg, MaterialRangeCfg, RobotDrCfg, SandFloorCfg, SandTerrainCfg

__all__ = ["main", "task_from_dict", "upgrade_policy_dir"]

_V1_KEYS = ("joint_names", "joint_stiffness", "joint_damping", "default_joint_pos", "action_scale",
            "observation_names", "observation_dims", "observation_scale", "observation_clip", "history_length",
            "policy_dt", "history_padding", "latent_dim", "commit", "run_path", "format")  # fmt: skip
"""Entries of the version-1 student metadata."""
_NESTED: dict[str, type] = {"terrain": SandTerrainCfg, "floor": SandFloorCfg, "material": MaterialRangeCfg,
                            "robot_dr": RobotDrCfg}  # fmt: skip
"""Dataclass-valued fields of the task config."""


def _tuples(value: Any) -> Any:
    """JSON lists back to tuples (the config's range fields)."""
    return tuple(_tuples(v) for v in value) if isinstance(value, list) else value


def _build(cls: type, doc: Mapping[str, Any], where: str) -> Any:
    """Build ``cls`` from ``doc``; every field must be present."""
    names = [f.name for f in fields(cls)]
    missing = [f"{where}{n}" for n in names if n not in doc]
    if missing:
        raise ValueError(f"train_cfg.json lacks {missing}; give each with --set key=value if the repository says it.")
    kwargs = {}
    for n in names:
        v = doc[n]
        kwargs[n] = (
            _build(_NESTED[n], v, f"{where}{n}.") if n in _NESTED else (v if n == "reward_weights" else _tuples(v))
        )
    return cls(**kwargs)


def task_from_dict(doc: Mapping[str, Any], overrides: Mapping[str, Any] | None = None) -> GranularTaskCfg:
    """Return the task of a ``train_cfg.json`` ``task`` entry (top-level ``overrides`` fill absent fields).

    Raises:
        ValueError: If a field is absent and not overridden.
    """
    return _build(GranularTaskCfg, {**doc, **(overrides or {})}, "task.")


def upgrade_policy_dir(folder: Path, overrides: Mapping[str, Any] | None = None) -> Path:
    """Rewrite ``folder/policy.onnx`` (+ ``policy.json``) with the versioned document; return the ONNX path.

    Raises:
        ValueError: If the file has no version-1 entries, or the facts disagree (history length, inputs).
    """
    from gmloco.deploy.export import write_policy_metadata
    from gmloco.train.tasks.g1_granular.policy_metadata import granular_policy_metadata, joint_spec

    path, cfg = folder / "policy.onnx", json.loads((folder / "train_cfg.json").read_text())
    model = onnx.load(str(path))
    props = {p.key: json.loads(p.value) for p in model.metadata_props if p.key in _V1_KEYS}
    if props.get("format") != "gmloco-student-policy/1":
        raise ValueError(f"{path} has no version-1 student metadata to upgrade.")
    if props["history_length"] != cfg["history_length"]:
        raise ValueError(f"history length {props['history_length']} (file) != {cfg['history_length']} (train_cfg).")
    joints = joint_spec(props["joint_names"], props["joint_stiffness"], props["joint_damping"],
                        props["default_joint_pos"], props["action_scale"])  # fmt: skip
    meta = granular_policy_metadata(
        task_from_dict(cfg["task"], overrides), joints, props["observation_dims"], layout="frame_and_history",
        history_length=props["history_length"], policy_class="StudentActor", latent_dim=props["latent_dim"],
        run_path=props["run_path"], commit=props["commit"],
    )  # fmt: skip
    if abs(meta.timing.policy_dt - props["policy_dt"]) > 1e-9:
        raise ValueError(f"policy dt {props['policy_dt']} (file) != {meta.timing.policy_dt} (task).")
    kept = [p for p in model.metadata_props if p.key not in _V1_KEYS]
    del model.metadata_props[:]
    model.metadata_props.extend(kept)
    tmp = folder / ".policy.onnx.upgrade.tmp"
    onnx.save(model, str(tmp))
    write_policy_metadata(tmp, meta)
    os.replace(tmp, path)
    tmp_json = folder / ".policy.json.upgrade.tmp"
    tmp_json.write_text(json.dumps(meta.to_dict(), indent=1) + "\n")
    os.replace(tmp_json, folder / "policy.json")
    return path


def _value(text: str) -> Any:
    """A ``--set`` value: JSON where it parses (``0.5``, ``[1, 2]``), else the text (``sole``)."""
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def main(argv: Sequence[str] | None = None) -> int:
    """Upgrade each given policy folder; return the exit code."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("folders", nargs="+", type=Path, help="folders holding policy.onnx and train_cfg.json")
    parser.add_argument("--set", action="append", default=[], help="task field absent from train_cfg.json, key=value")
    args = parser.parse_args(argv)
    overrides = {key: _value(text) for key, text in (item.split("=", 1) for item in args.set)}
    for folder in args.folders:
        try:
            print(upgrade_policy_dir(folder, overrides))
        except (OSError, ValueError, KeyError) as err:
            print(f"upgrade_metadata: {folder}: {err}", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
