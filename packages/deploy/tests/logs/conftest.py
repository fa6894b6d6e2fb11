# SPDX-License-Identifier: Apache-2.0
"""Fixtures: small synthetic G1 logs written with the real writer."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from gmloco.deploy.logs import G1_JOINT_NAMES, G1LogWriter, LogWriterCfg, RunMetadata
from gmloco.deploy.logs.schema import TOPICS

SAMPLES = Path(__file__).resolve().parents[2] / "data/sample_logs"


@dataclass
class Synthetic:
    """Arrays written into a synthetic log (canonical joint order)."""

    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    tau: np.ndarray
    quat: np.ndarray
    gyro: np.ndarray
    acc: np.ndarray
    rpy: np.ndarray
    cmd_q: np.ndarray
    kp: np.ndarray
    kd: np.ndarray
    t_ctrl: np.ndarray
    vx: np.ndarray
    obs: np.ndarray
    action: np.ndarray
    eta: np.ndarray
    pos: np.ndarray
    vel: np.ndarray
    temp: np.ndarray
    vol: np.ndarray
    contact: np.ndarray
    force: np.ndarray
    extra: dict = field(default_factory=dict)


def make_synthetic(n: int = 300, rate: float = 200.0, seed: int = 0) -> Synthetic:
    """Random but plausible arrays: joints near zero, upright IMU, 4:1 control decimation."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate
    yaw = 0.3 * np.sin(t)
    quat = np.stack([np.cos(yaw / 2), 0 * t, 0 * t, np.sin(yaw / 2)], 1)
    t_ctrl = t[::4]
    k = len(t_ctrl)
    return Synthetic(
        t=t,
        q=rng.uniform(-0.3, 0.3, (n, 29)),
        dq=rng.normal(size=(n, 29)),
        ddq=rng.normal(size=(n, 29)),
        tau=rng.normal(size=(n, 29)) * 10,
        quat=quat,
        gyro=rng.normal(size=(n, 3)),
        acc=np.array([0, 0, 9.81]) + rng.normal(size=(n, 3)) * 0.1,
        rpy=rng.normal(size=(n, 3)) * 0.1,
        cmd_q=rng.uniform(-0.3, 0.3, (n, 29)),
        kp=np.full((n, 29), 100.0),
        kd=np.full((n, 29), 2.0),
        t_ctrl=t_ctrl,
        vx=np.repeat([0.0, 0.5], [k // 2, k - k // 2]),
        obs=rng.normal(size=(k, 7)),
        action=rng.normal(size=(k, 29)),
        eta=rng.normal(size=(k, 2)),
        pos=rng.normal(size=(n, 3)),
        vel=rng.normal(size=(n, 3)),
        temp=rng.uniform(20, 60, (n, 29, 2)),
        vol=rng.uniform(40, 50, (n, 29)),
        contact=rng.random((n, 2)) > 0.5,
        force=rng.normal(size=(n, 2, 3)) * 100,
    )


def write_synthetic(
    path: Path,
    s: Synthetic,
    *,
    joint_order: tuple[str, ...] = G1_JOINT_NAMES,
    skip: tuple[str, ...] = (),
    chunk_size: int = 16 * 1024,
    meta: RunMetadata | None = None,
) -> Path:
    """Write ``s`` to ``path`` with every topic except those in ``skip``; arrays permuted to ``joint_order``."""
    perm = [G1_JOINT_NAMES.index(n) for n in joint_order]
    meta = meta or RunMetadata(controller="policy", policy="test.onnx", material="sand_loose", joint_names=joint_order)
    topics = tuple(t for t, sp in TOPICS.items() if sp.required and t not in skip)
    with G1LogWriter(path, meta, LogWriterCfg(chunk_size=chunk_size, topics=topics)) as w:
        if "/student/eta" not in skip:
            w.declare("/student/eta", names=["stiffness", "friction"], units=["1", "1"])
        if "/policy/observation" not in skip:
            w.declare("/policy/observation", terms=[["base_ang_vel", 3], ["projected_gravity", 3], ["cmd", 1]])
        c = 0
        for i, t in enumerate(s.t):
            if "/lowstate/joint_states" not in skip:
                w.write_lowstate(t, s.q[i, perm], s.dq[i, perm], s.tau[i, perm], s.quat[i], s.gyro[i], s.acc[i],
                                 ddq=s.ddq[i, perm], rpy=s.rpy[i], tick=1000 + i)  # fmt: skip
            if "/lowcmd" not in skip:
                w.write_lowcmd(t, s.cmd_q[i, perm], 0 * s.cmd_q[i], s.kp[i, perm], s.kd[i, perm], 0 * s.cmd_q[i])
            if "/lowstate/motor_aux" not in skip:
                w.write_motor_aux(t, s.temp[i, perm], s.vol[i, perm])
            if "/odometry" not in skip:
                w.write_odometry(t, s.pos[i], s.quat[i], s.vel[i], s.gyro[i])
            if "/sim/foot_contact" not in skip:
                w.write_sim_contact(t, s.contact[i], s.force[i], np.zeros(2))
            if c < len(s.t_ctrl) and np.isclose(s.t_ctrl[c], t):
                if "/command/velocity" not in skip:
                    w.write_command(t, s.vx[c])
                if "/policy/observation" not in skip:
                    w.write_policy(t, observation=s.obs[c], action=s.action[c])
                if "/student/eta" not in skip:
                    w.write_eta(t, s.eta[c])
                c += 1
        if "/log" not in skip:
            w.write_log(0.5, "stage S2: stepping in place", "INFO")
    return path


@pytest.fixture
def synthetic() -> Synthetic:
    """Synthetic arrays (300 samples at 200 Hz)."""
    return make_synthetic()


@pytest.fixture
def synthetic_log(tmp_path: Path, synthetic: Synthetic) -> Path:
    """A complete synthetic log file."""
    return write_synthetic(tmp_path / "synthetic.mcap", synthetic)


@pytest.fixture
def write_log() -> object:
    """The :func:`write_synthetic` helper (test modules cannot import conftest under importlib mode)."""
    return write_synthetic


@pytest.fixture
def samples_dir() -> Path:
    """Directory of the committed sample recordings."""
    return SAMPLES
