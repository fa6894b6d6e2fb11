# SPDX-License-Identifier: Apache-2.0
"""Add the versioned metadata document to an ONNX policy exported before it existed, from facts beside it.

``python -m gmloco.train.tasks.g1_granular.upgrade_metadata <policy_dir> [--set key=value ...]`` reads the
policy's ``train_cfg.json`` (the training task) and the file's own older entries, adds the G1 effort limits and
everything the task determines, then rewrites ``policy.onnx`` (atomically) and ``policy.json``. Two older forms:

* a version-1 student (``format: gmloco-student-policy/1``, JSON values: joints, kp/kd, default pose, action
  scale, term widths, history length, latent size, commit and run, read from the live env at export); its
  version-1 entries are replaced by the document;
* an mjlab actor export (PPO; comma-joined values: joints, kp/kd, default pose, action scale, term names and
  widths, stacked history length, policy dt, contact model); its mjlab entries are kept beside the document, as
  :func:`gmloco.train.rl.export.export_policy_onnx` writes them, and the commit is the last training chunk's in
  ``manifest.json``.
 A task field missing from ``train_cfg.json`` is refused unless
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

from gmloco.deploy.export import METADATA_KEY, write_policy_metadata
from gmloco.train.config import GranularTaskCfg, MaterialRangeCfg, RobotDrCfg, SandFloorCfg, SandTerrainCfg

__all__ = ["main", "task_from_dict", "upgrade_policy_dir"]

_V1_KEYS = ("joint_names", "joint_stiffness", "joint_damping", "default_joint_pos", "action_scale",
            "observation_names", "observation_dims", "observation_scale", "observation_clip", "history_length",
            "policy_dt", "history_padding", "latent_dim", "commit", "run_path", "format")  # fmt: skip
"""Entries of the version-1 student metadata."""
_MJLAB_KEYS = ("joint_names", "joint_stiffness", "joint_damping", "default_joint_pos", "action_scale",
               "observation_names", "observation_dims", "observation_history_length", "policy_dt", "run_path")  # fmt: skip
"""Entries of mjlab's actor export (``gmloco.train.rl.export.policy_metadata``) that the upgrade reads."""
_NESTED: dict[str, type] = {"terrain": SandTerrainCfg, "floor": SandFloorCfg, "material": MaterialRangeCfg,
                            "robot_dr": RobotDrCfg}  # fmt: skip
"""Dataclass-valued fields of the task config."""


_ADDED_LATER: dict[str, Any] = {
    "task.terrain.floor.promotion": "distance",
    "task.material.soft_share": 0.0,
    "task.material.soft_rho_c": (500.0, 800.0),
}
"""Task fields added after runs were saved, with the value that reproduces every run saved without them (the only
behaviour there was): such a field is filled in, never guessed for any other key."""


def _tuples(value: Any) -> Any:
    """JSON lists back to tuples (the config's range fields)."""
    return tuple(_tuples(v) for v in value) if isinstance(value, list) else value


def _build(cls: type, doc: Mapping[str, Any], where: str) -> Any:
    """Build ``cls`` from ``doc``; every field must be present."""
    names = [f.name for f in fields(cls)]
    doc = {**{n: _ADDED_LATER[f"{where}{n}"] for n in names if f"{where}{n}" in _ADDED_LATER}, **doc}
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


def _floats(text: str) -> list[float]:
    """An mjlab comma-joined value as floats."""
    return [float(x) for x in text.split(",")]


def _student_meta(props: Mapping[str, str], cfg: Mapping[str, Any], overrides: Mapping[str, Any] | None) -> Any:
    """The document of a version-1 student from its JSON entries and ``train_cfg.json``."""
    from gmloco.train.tasks.g1_granular.policy_metadata import granular_policy_metadata, joint_spec

    v1 = {k: json.loads(v) for k, v in props.items() if k in _V1_KEYS}
    if v1["history_length"] != cfg["history_length"]:
        raise ValueError(f"history length {v1['history_length']} (file) != {cfg['history_length']} (train_cfg).")
    joints = joint_spec(v1["joint_names"], v1["joint_stiffness"], v1["joint_damping"],
                        v1["default_joint_pos"], v1["action_scale"])  # fmt: skip
    meta = granular_policy_metadata(
        task_from_dict(cfg["task"], overrides), joints, v1["observation_dims"], layout="frame_and_history",
        history_length=v1["history_length"], policy_class="StudentActor", latent_dim=v1["latent_dim"],
        run_path=v1["run_path"], commit=v1["commit"],
    )  # fmt: skip
    if abs(meta.timing.policy_dt - v1["policy_dt"]) > 1e-9:
        raise ValueError(f"policy dt {v1['policy_dt']} (file) != {meta.timing.policy_dt} (task).")
    return meta


def _mjlab_meta(
    props: Mapping[str, str], cfg: Mapping[str, Any], overrides: Mapping[str, Any] | None, commit: str
) -> Any:
    """The document of an mjlab actor export (PPO, ``term_stacked``) from its entries and ``train_cfg.json``."""
    from gmloco.train.tasks.g1_granular.policy_metadata import granular_policy_metadata, joint_spec

    missing = [k for k in _MJLAB_KEYS if k not in props]
    if missing:
        raise ValueError(f"the file lacks the mjlab export entries {missing}.")
    task = task_from_dict(cfg["task"], overrides)
    history = int(props["observation_history_length"])
    if history != task.policy_history_length:
        raise ValueError(f"stacked history {history} (file) != {task.policy_history_length} (train_cfg task).")
    if props.get("contact_model", task.contact_model) != task.contact_model:
        raise ValueError(f"contact model {props['contact_model']} (file) != {task.contact_model} (train_cfg task).")
    scale = _floats(props["action_scale"])
    joints = joint_spec(props["joint_names"].split(","), _floats(props["joint_stiffness"]),
                        _floats(props["joint_damping"]), _floats(props["default_joint_pos"]),
                        scale[0] if len(scale) == 1 else scale)  # fmt: skip
    dims = [round(d) for d in _floats(props["observation_dims"])]
    meta = granular_policy_metadata(task, joints, dims, layout="term_stacked", history_length=history,
                                    policy_class="MLPModel", run_path=props["run_path"], commit=commit)  # fmt: skip
    names = props["observation_names"].split(",")
    if names != [t.name for t in meta.observation.terms]:
        raise ValueError(f"actor terms {names} (file) != {[t.name for t in meta.observation.terms]} (task).")
    if abs(meta.timing.policy_dt - float(props["policy_dt"])) > 1e-9:
        raise ValueError(f"policy dt {props['policy_dt']} (file) != {meta.timing.policy_dt} (task).")
    return meta


def _training_commit(folder: Path) -> str:
    """Commit of the last training chunk in ``folder/manifest.json`` ('unknown' without one)."""
    path = folder / "manifest.json"
    chunks = json.loads(path.read_text()).get("chunks", []) if path.exists() else []
    return str(chunks[-1].get("commit", "unknown")) if chunks else "unknown"


def upgrade_policy_dir(folder: Path, overrides: Mapping[str, Any] | None = None) -> Path:
    """Rewrite ``folder/policy.onnx`` (+ ``policy.json``) with the versioned document; return the ONNX path.

    Raises:
        ValueError: If the file has neither version-1 student nor mjlab export entries, or the facts disagree
            (history length, actor terms, policy dt, contact model).
    """
    path, cfg = folder / "policy.onnx", json.loads((folder / "train_cfg.json").read_text())
    model = onnx.load(str(path))
    props = {p.key: p.value for p in model.metadata_props}
    if props.get("format") == json.dumps("gmloco-student-policy/1"):
        meta, dropped = _student_meta(props, cfg, overrides), set(_V1_KEYS)
    elif "observation_history_length" in props and METADATA_KEY not in props:
        meta, dropped = _mjlab_meta(props, cfg, overrides, _training_commit(folder)), set()
    else:
        raise ValueError(f"{path} has neither version-1 student metadata nor an mjlab export's to upgrade.")
    kept = [p for p in model.metadata_props if p.key not in dropped]
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
