# SPDX-License-Identifier: Apache-2.0
"""Deploy metadata from the training task: effort limits, collider, threshold, stages; upgrading version-1 files."""

from __future__ import annotations

import json
from dataclasses import asdict, replace
from pathlib import Path

import onnx
import pytest
from onnx import TensorProto, helper

from gmloco.deploy.export import METADATA_KEY, JointSpec, PolicyMetadata, read_policy_metadata
from gmloco.deploy.g1 import G1_JOINT_NAMES
from gmloco.train.tasks.g1_granular import g1_granular_task
from gmloco.train.tasks.g1_granular.policy_metadata import granular_policy_metadata, joint_spec
from gmloco.train.tasks.g1_granular.upgrade_metadata import upgrade_policy_dir

DIMS = [3, 3, 3, 29, 29, 29]
"""Per-frame widths of the G1 actor terms."""


def _joints() -> JointSpec:
    """G1 joints with placeholder gains."""
    return joint_spec(G1_JOINT_NAMES, [1.0] * 29, [0.1] * 29, [0.0] * 29, 0.25)


def test_metadata_follows_the_training_task() -> None:
    """Take effort limits, collider, threshold, command stages and timing from the task.

    Hand values: knee 139, hip pitch 88, ankle 2 x 25, wrist pitch 5 N m; box faces; 40 N granular threshold;
    stages at 0.1 x (240k, 360k) env steps; 200 Hz physics x 4 = 50 Hz policy; JSON round trip exact.
    """
    task = replace(g1_granular_task("rft3d"), foot_faces="box", curriculum_scale=0.1)
    meta = granular_policy_metadata(
        task,
        _joints(),
        DIMS,
        layout="frame_and_history",
        history_length=50,
        policy_class="StudentActor",
    )
    limits = dict(zip(meta.joints.names, meta.joints.effort_limit, strict=True))
    assert (limits["left_knee_joint"], limits["right_hip_pitch_joint"]) == (139.0, 88.0)
    assert (limits["left_ankle_roll_joint"], limits["left_wrist_pitch_joint"]) == (50.0, 5.0)
    assert meta.contact.foot_collider.faces == "box" and meta.contact.contact_force_threshold == 40.0
    assert [s["step"] for s in meta.command.stages] == [0, 24_000, 36_000]
    assert (meta.timing.physics_dt, meta.timing.decimation, meta.timing.policy_dt) == (0.005, 4, 0.02)
    assert [t.name for t in meta.observation.terms][:3] == ["base_ang_vel", "projected_gravity", "command"]
    assert PolicyMetadata.from_props(meta.to_props()) == meta


def test_metadata_states_the_heading_rule() -> None:
    """The yaw-target task records its k (2/s here) and the correction; mjlab's heading envs record their 0.5/s."""
    kw = {"layout": "frame_and_history", "history_length": 50, "policy_class": "StudentActor"}
    target = replace(g1_granular_task("rft3d"), yaw_command="yaw_target", heading_stiffness=2.0)
    cmd = granular_policy_metadata(target, _joints(), DIMS, **kw).command  # type: ignore[arg-type]
    assert (cmd.yaw_command, cmd.heading_stiffness) == ("yaw_target", 2.0)
    assert "clip(omega_z + 2 * wrap(yaw_target - yaw)" in cmd.description
    envs = replace(target, yaw_command="heading_envs")
    cmd = granular_policy_metadata(envs, _joints(), DIMS, **kw).command  # type: ignore[arg-type]
    assert (cmd.yaw_command, cmd.heading_stiffness) == ("heading_envs", 0.5)


def test_committed_students_state_mjlab_heading_envs() -> None:
    """The committed students were trained before the yaw target: their metadata says heading envs, k = 0.5/s."""
    root = Path(__file__).resolve().parents[3] / "artifacts"
    for name in ("gm_loco_student_td", "gm_loco_student_clr50"):
        cmd = read_policy_metadata(root / name / "policy.onnx").command
        assert (cmd.yaw_command, cmd.heading_stiffness) == ("heading_envs", 0.5), name


def test_rigid_policy_records_the_rigid_threshold_and_the_sole() -> None:
    """Rigid contact: 5 N threshold; the collider (kept for logging) stays the sole whatever foot_faces says."""
    task = replace(g1_granular_task("rigid"), foot_faces="box")
    meta = granular_policy_metadata(
        task, _joints(), DIMS, layout="term_stacked", history_length=5, policy_class="MLPModel"
    )
    assert meta.contact.model == "rigid" and meta.contact.contact_force_threshold == 5.0
    assert meta.contact.foot_collider.faces == "sole"


def _v1_policy(folder: Path, history: int = 50) -> None:
    """A one-node ONNX with version-1 student entries, and a train_cfg.json whose task lacks ``foot_faces``."""
    x = helper.make_tensor_value_info("x", TensorProto.FLOAT, [1])
    y = helper.make_tensor_value_info("y", TensorProto.FLOAT, [1])
    model = helper.make_model(helper.make_graph([helper.make_node("Identity", ["x"], ["y"])], "g", [x], [y]))
    v1 = {
        "joint_names": list(G1_JOINT_NAMES), "joint_stiffness": [40.0] * 29, "joint_damping": [2.0] * 29,
        "default_joint_pos": [0.1] * 29, "action_scale": [0.25] * 29, "observation_dims": DIMS,
        "history_length": history, "policy_dt": 0.02, "latent_dim": 16, "commit": "abc", "run_path": "r/model_1.pt",
        "format": "gmloco-student-policy/1", "observation_names": ["a"], "other": "kept",
    }  # fmt: skip
    for key, value in v1.items():
        model.metadata_props.append(onnx.StringStringEntryProto(key=key, value=json.dumps(value)))
    onnx.save(model, str(folder / "policy.onnx"))
    task = asdict(g1_granular_task())
    del task["foot_faces"]
    (folder / "train_cfg.json").write_text(json.dumps({"task": task, "history_length": 50}))


def test_upgrade_refuses_a_missing_task_field_then_writes_the_document(tmp_path: Path) -> None:
    """Without foot_faces the upgrade is refused; given it, the file carries the document and no version-1 entry."""
    _v1_policy(tmp_path)
    with pytest.raises(ValueError, match="foot_faces"):
        upgrade_policy_dir(tmp_path)
    upgrade_policy_dir(tmp_path, {"foot_faces": "sole"})
    meta = read_policy_metadata(tmp_path / "policy.onnx")
    assert meta.joints.stiffness == [40.0] * 29 and meta.commit == "abc" and meta.observation.history_length == 50
    assert meta.contact.foot_collider.faces == "sole" and meta.latent_dim == 16
    keys = {p.key for p in onnx.load(str(tmp_path / "policy.onnx")).metadata_props}
    assert keys == {METADATA_KEY, "other"}
    assert json.loads((tmp_path / "policy.json").read_text()) == meta.to_dict()


def test_task_saved_before_the_floor_rule_reads_as_the_distance_rule() -> None:
    """A train_cfg task without ``terrain.floor.promotion`` (saved before the field) is read with its only rule then."""
    from gmloco.train.tasks.g1_granular.upgrade_metadata import task_from_dict

    task = asdict(replace(g1_granular_task(), foot_faces="box"))
    del task["terrain"]["floor"]["promotion"]
    rebuilt = task_from_dict(json.loads(json.dumps(task)))
    assert rebuilt.terrain.floor.promotion == "distance" and rebuilt.foot_faces == "box"


def test_task_saved_before_the_soft_share_reads_as_gm_locos_draw() -> None:
    """A train_cfg task without the material's soft share (saved before the field) is read with none (0)."""
    from gmloco.train.tasks.g1_granular.upgrade_metadata import task_from_dict

    task = asdict(g1_granular_task())
    del task["material"]["soft_share"], task["material"]["soft_rho_c"]
    rebuilt = task_from_dict(json.loads(json.dumps(task)))
    assert rebuilt.material == g1_granular_task().material and rebuilt.material.soft_share == 0.0


def test_upgrade_refuses_disagreeing_facts(tmp_path: Path) -> None:
    """A file whose history length differs from its train_cfg.json is not upgraded."""
    _v1_policy(tmp_path, history=40)
    with pytest.raises(ValueError, match="history length"):
        upgrade_policy_dir(tmp_path, {"foot_faces": "sole"})


def _mjlab_policy(folder: Path, history: int = 5) -> None:
    """A one-node ONNX with an mjlab actor export's comma-joined entries, a train_cfg.json and a manifest.json."""
    x = helper.make_tensor_value_info("obs", TensorProto.FLOAT, [1, 480])
    y = helper.make_tensor_value_info("actions", TensorProto.FLOAT, [1, 480])
    model = helper.make_model(helper.make_graph([helper.make_node("Identity", ["obs"], ["actions"])], "g", [x], [y]))
    entries = {
        "run_path": "ppo_rft3d", "joint_names": ",".join(G1_JOINT_NAMES), "joint_stiffness": ",".join(["40.0"] * 29),
        "joint_damping": ",".join(["2.0"] * 29), "default_joint_pos": ",".join(["0.1"] * 29), "action_scale": "0.25",
        "observation_names": "base_ang_vel,projected_gravity,command,joint_pos,joint_vel,actions",
        "observation_dims": ",".join(f"{d:.3f}" for d in DIMS), "observation_history_length": str(history),
        "policy_dt": "0.02", "contact_model": "rft3d",
    }  # fmt: skip
    for key, value in entries.items():
        model.metadata_props.append(onnx.StringStringEntryProto(key=key, value=value))
    onnx.save(model, str(folder / "policy.onnx"))
    task = asdict(g1_granular_task())
    (folder / "train_cfg.json").write_text(json.dumps({"task": task, "history_length": 0}))
    (folder / "manifest.json").write_text(json.dumps({"chunks": [{"commit": "aaa"}, {"commit": "bbb"}]}))


def test_upgrade_of_an_mjlab_export_keeps_its_entries_and_adds_the_document(tmp_path: Path) -> None:
    """PPO export: term-stacked MLP document, 5 frames, commit of the last chunk; mjlab's keys stay for mjlab tools."""
    _mjlab_policy(tmp_path)
    upgrade_policy_dir(tmp_path)
    meta = read_policy_metadata(tmp_path / "policy.onnx")
    assert (meta.observation.layout, meta.observation.history_length, meta.policy_class) == (
        "term_stacked",
        5,
        "MLPModel",
    )
    assert meta.commit == "bbb" and meta.joints.action_scale == [0.25] * 29 and meta.joints.stiffness == [40.0] * 29
    assert [t.dim for t in meta.observation.terms] == DIMS
    keys = {p.key for p in onnx.load(str(tmp_path / "policy.onnx")).metadata_props}
    assert METADATA_KEY in keys and "observation_history_length" in keys
    with pytest.raises(ValueError, match="neither"):  # a second upgrade finds the document and refuses
        upgrade_policy_dir(tmp_path)


def test_upgrade_of_an_mjlab_export_refuses_a_different_history(tmp_path: Path) -> None:
    """A file stacking 4 frames for a task of 5 is not upgraded."""
    _mjlab_policy(tmp_path, history=4)
    with pytest.raises(ValueError, match="stacked history 4"):
        upgrade_policy_dir(tmp_path)
