# SPDX-License-Identifier: Apache-2.0
"""gmloco.train.recording: the mjlab env recorded in the deploy log schema, read back with read_log."""

from __future__ import annotations

import random
import warnings
from pathlib import Path

import numpy as np
import pytest
import torch

from gmloco.train import EvalCfg, evaluate_policy, g1_granular_task
from gmloco.train.recording import EnvRecorder, RecordingCfg, joint_permutation, policy_run_metadata

logs = pytest.importorskip("gmloco.deploy.logs")
G1Log = logs.G1Log

STEPS = 5


def test_joint_permutation_by_name() -> None:
    """A shuffled joint order maps back to the canonical order by name; bad name sets are refused."""
    names = list(logs.G1_JOINT_NAMES)
    shuffled = names[:]
    random.Random(0).shuffle(shuffled)
    perm = joint_permutation([f"robot/{n}" for n in shuffled])
    assert [shuffled[i] for i in perm] == names
    values = np.arange(len(names), dtype=float)  # value = canonical index
    assert np.array_equal(np.array([names.index(n) for n in shuffled], dtype=float)[perm], values)
    with pytest.raises(ValueError, match="missing"):
        joint_permutation(shuffled[:-1])
    with pytest.raises(ValueError, match="duplicated"):
        joint_permutation([*shuffled[:-1], shuffled[0]])
    with pytest.raises(ValueError, match="unknown"):
        joint_permutation([*shuffled[:-1], "tail_joint"])


def _read(path: Path) -> G1Log:
    """read_log, failing on any contract or damage warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", logs.LogContractWarning)
        warnings.simplefilter("error", logs.LogDamageWarning)
        return logs.read_log(path)


def test_recorder_round_trip(make_env, tmp_path: Path) -> None:  # noqa: ANN001
    """Env 1 of 2 for a few steps: shapes, monotonic time, joint order by name, units, metadata, end record."""
    env = make_env(g1_granular_task("rft3d"), num_envs=2)
    policy = tmp_path / "policy.onnx"
    policy.write_bytes(b"not a real policy")
    meta = policy_run_metadata(
        policy_path=str(policy),
        onnx_meta={"run_path": "unit_test", "action_scale": "0.25"},
        material="dry_sand",
        contact_model="rft3d",
        terrain="flat",
        control_rate_hz=1.0 / env.step_dt,
        notes="unit test",
    )
    path = tmp_path / "run.mcap"
    obs, _ = env.reset()
    rec = EnvRecorder(env, path, meta, RecordingCfg(env_index=1))
    gen = torch.Generator().manual_seed(0)
    actions = []
    for _ in range(STEPS):
        actions.append(0.2 * torch.randn(2, 29, generator=gen))
        rec.before_step(obs["actor"], actions[-1])
        obs, _, terminated, _, _ = env.step(actions[-1])
        rec.after_step(terminated)
    robot = env.scene["robot"]
    q_final = robot.data.joint_pos[1].numpy().copy()
    assert rec.close() == path and path.exists()
    log = _read(path)

    md = log.metadata
    assert md.controller == "policy:unit_test" and md.source == "sim" and md.material == "dry_sand"
    assert md.contact_model == "rft3d" and md.commit and md.notes == "unit test"
    assert md.control_rate_hz == pytest.approx(50.0) and md.units == dict(logs.UNITS)
    for key in ("policy_path", "policy_sha256", "policy_metadata", "terrain", "signal_sources", "material_params"):
        assert key in md.extra
    assert log.run_end is not None and log.run_end["end_reason"] == "completed"

    n_obs = obs["actor"].shape[1]
    expected = {
        "lowstate.q": (STEPS + 1, 29),
        "lowstate.tau_est": (STEPS + 1, 29),
        "imu.quaternion": (STEPS + 1, 4),
        "imu.accelerometer": (STEPS + 1, 3),
        "odom.position": (STEPS + 1, 3),
        "sim.force": (STEPS + 1, 2, 3),
        "sim.in_contact": (STEPS + 1, 2),
        "lowcmd.kp": (STEPS, 29),
        "policy.observation": (STEPS, n_obs),
        "policy.action": (STEPS, 29),
        "command.lin_vel_x": (STEPS,),
    }
    for signal, shape in expected.items():
        t, v = log.signal(signal)
        assert v.shape == shape, signal
        assert np.all(np.diff(t) > 0) and t[0] == 0.0, signal
        assert np.all(np.isfinite(v)), signal
    t, _ = log.signal("lowstate.q")
    np.testing.assert_allclose(t, np.arange(STEPS + 1) * env.step_dt, atol=1e-9)

    # Joint order by name: mjlab's joint order for states, its (different) actuator order for gains.
    for name in ("left_knee_joint", "right_ankle_pitch_joint", "waist_roll_joint", "left_shoulder_pitch_joint"):
        _, q = log.signal("lowstate.q", joint=name)
        assert np.float32(q[-1]) == q_final[robot.joint_names.index(name)]
        _, kp = log.signal("lowcmd.kp", joint=name)
        a = robot.actuator_names.index(name)
        gain = env.sim.model.actuator_gainprm[1, int(robot.indexing.ctrl_ids[a]), 0]
        assert np.float32(kp[-1]) == pytest.approx(float(gain), rel=1e-6)
    _, quat = log.signal("imu.quaternion")
    np.testing.assert_allclose(np.linalg.norm(quat, axis=1), 1.0, atol=1e-5)
    _, action = log.signal("policy.action")
    np.testing.assert_array_equal(action.astype(np.float32), torch.stack(actions)[:, 1].numpy())
    _, q_cmd = log.signal("lowcmd.q")  # target = raw action * scale + default pose, by name
    term = env.action_manager.get_term("joint_pos")
    j = list(term.target_names).index("left_knee_joint")
    expected_cmd = (
        actions[-1][1, j] * term.scale + robot.data.default_joint_pos[1, robot.joint_names.index("left_knee_joint")]
    )
    _, q_knee_cmd = log.signal("lowcmd.q", joint="left_knee_joint")
    assert q_knee_cmd[-1] == pytest.approx(float(expected_cmd), abs=1e-6) and q_cmd.shape == (STEPS, 29)


def _tiny_policy(path: Path, obs_dim: int) -> None:
    """A zero-action ONNX policy with the export metadata evaluate_policy reads (history 1)."""
    import onnx
    from onnx import TensorProto, helper, numpy_helper

    weight = numpy_helper.from_array(np.zeros((obs_dim, 29), dtype=np.float32), name="w")
    graph = helper.make_graph(
        [helper.make_node("MatMul", ["obs", "w"], ["actions"])],
        "tiny",
        [helper.make_tensor_value_info("obs", TensorProto.FLOAT, [1, obs_dim])],
        [helper.make_tensor_value_info("actions", TensorProto.FLOAT, [1, 29])],
        initializer=[weight],
    )
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)])
    model.ir_version = 8
    for key, value in {
        "run_path": "tiny",
        "observation_history_length": "1",
        "action_scale": "0.25",
        "contact_model": "rft3d",
    }.items():
        model.metadata_props.add(key=key, value=value)
    onnx.save(model, str(path))


def test_evaluate_policy_records_one_file_per_cell(tmp_path: Path) -> None:
    """EvalCfg.record_dir: one readable recording per (material, speed) cell, env 0 of the cell, same metrics."""
    policy = tmp_path / "policy.onnx"
    _tiny_policy(policy, obs_dim=96)
    cfg = EvalCfg(
        policy_path=str(policy),
        materials=("dry_sand", "poppy_seed"),
        speeds=(0.5,),
        repeats=1,
        duration_s=0.1,
        record_dir=str(tmp_path / "rec"),
        record_notes="tiny zero-action policy",
    )
    metrics = evaluate_policy(cfg)
    assert metrics["all/num_envs"] == 2.0
    files = sorted((tmp_path / "rec").glob("*.mcap"))
    assert [f.name for f in files] == ["g1_tiny_dry_sand_v0.5.mcap", "g1_tiny_poppy_seed_v0.5.mcap"]
    for f, material, k in zip(files, ("dry_sand", "poppy_seed"), (0, 1), strict=True):
        log = _read(f)
        assert log.metadata.controller == "policy:tiny" and log.metadata.material == material
        assert log.metadata.notes == "tiny zero-action policy"
        assert log.metadata.extra["env_index"] == str(k)
        _, cmd = log.signal("command.lin_vel_x")
        np.testing.assert_allclose(cmd, 0.5)
        _, obs = log.signal("policy.observation")
        assert obs.shape == (5, 96)
        _, q = log.signal("lowstate.q")
        assert q.shape == (6, 29)
