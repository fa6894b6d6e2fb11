# SPDX-License-Identifier: Apache-2.0
"""Record one env of the granular training simulator (the mjlab env) in the project's MCAP schema.

:class:`EnvRecorder` writes env ``k`` of a ``ManagerBasedRlEnv`` of any size through the deploy package's
:class:`~gmloco.deploy.logs.G1LogWriter` (schema ``gmloco.g1_log/1``, ``packages/deploy/SCHEMA.md``), once per
policy step (50 Hz; ``lowstate_rate_hz`` = ``control_rate_hz`` = 1 / ``env.step_dt`` in the run metadata, not
the robot's 500 Hz). Call order per policy step ``i`` (``t_i = i * env.step_dt``)::

    rec.before_step(obs_actor, action)   # state x_i (LowState, IMU, odometry, contact), command, obs_i, action_i
    obs, _, terminated, _, _ = env.step(action)
    rec.after_step(terminated)           # LowCmd sent during [t_i, t_i+1); closes the file if env k terminated
    ...
    rec.close()                          # final state x_N, end record ("completed" or "fell at t=...")

Where each signal comes from (also in the run metadata, key ``signal_sources``):

* ``lowstate.q`` / ``dq`` / ``ddq``: ``robot.data.joint_pos`` / ``joint_vel`` / ``joint_acc``; ``tau_est``: the
  actuator force in joint space (``robot.data.qfrc_actuator``: the MuJoCo position actuator's PD torque at
  x_i with the previous step's target, i.e. what the motors apply at that instant).
* IMU: the mjlab G1 MJCF's own sensors on site ``imu_in_pelvis``: ``gyro`` (``robot/imu_ang_vel``) and
  ``accelerometer`` (``robot/imu_lin_acc``, specific force, +9.81 on z at rest); orientation = the site's world
  quaternion (the site is aligned with the pelvis).
* ``/lowcmd``: ``q`` = raw action * action scale + default pose (the targets of the ``joint_pos`` action term),
  ``dq`` = 0, ``tau`` = 0 (no feed-forward), ``kp`` / ``kd`` = the actuators' gains in the simulator for env k
  (``actuator_gainprm[0]`` and ``-actuator_biasprm[2]``, actuator gain randomization included).
* ``/odometry``: simulator truth of the pelvis (root link) relative to the env origin; velocities in the pelvis frame.
* ``/sim/foot_contact``: :class:`~gmloco.train.foot_contact.FootContactTracker` of ``env.sand``: granular + hard
  floor force on each foot (world frame), its 40 N (granular) contact threshold, and sinkage = depth of the sole
  site below the sand free surface (0 above it).
* ``/policy/observation``: the actor observation fed to the policy (channel metadata ``terms``: name and width
  of each term, history included); ``/policy/action``: raw policy output in the action term's joint order
  (channel metadata ``joint_names``, ``action_scale``).

Per-joint arrays are mapped from mjlab's joint (and actuator) order to the schema's canonical G1 order by name
(:func:`joint_permutation`); float32 simulator values are written with their shortest float32 decimal
representation (exact, and about half the size of float64 text).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

import gmloco.contact as gc
from gmloco.deploy.logs import G1_FEET, G1_JOINT_NAMES, G1LogWriter, LogWriterCfg, RunMetadata, git_commit
from gmloco.deploy.logs.rotations import quat_to_rpy
from gmloco.deploy.logs.schema import (
    TOPIC_COMMAND,
    TOPIC_IMU,
    TOPIC_JOINT_STATES,
    TOPIC_LOWCMD,
    TOPIC_ODOMETRY,
    TOPIC_POLICY_ACTION,
    TOPIC_POLICY_OBS,
    TOPIC_SIM_CONTACT,
    TOPIC_TF,
)

__all__ = [
    "EnvRecorder",
    "RecordingCfg",
    "joint_permutation",
    "policy_label",
    "policy_run_metadata",
    "recording_file_name",
]

IMU_SITE = "imu_in_pelvis"
"""IMU site of the mjlab G1 MJCF (pelvis IMU, same orientation as the pelvis)."""
IMU_GYRO_SENSOR = "robot/imu_ang_vel"
"""mjlab scene name of the gyro on :data:`IMU_SITE`."""
IMU_ACC_SENSOR = "robot/imu_lin_acc"
"""mjlab scene name of the accelerometer on :data:`IMU_SITE`."""
ACTION_TERM = "joint_pos"
"""Name of the joint-position action term of the granular G1 task."""
COMMAND_TERM = "twist"
"""Name of the velocity command term."""
OBS_GROUP = "actor"
"""Observation group fed to the policy."""

SIGNAL_SOURCES = {
    "lowstate.q/dq/ddq": "robot.data.joint_pos / joint_vel / joint_acc (true joint state, mjlab)",
    "lowstate.tau_est": "robot.data.qfrc_actuator: the position actuators' joint torque at the logged state",
    "imu.quaternion": f"world quaternion of site {IMU_SITE} (aligned with the pelvis)",
    "imu.gyroscope": f"MuJoCo gyro sensor {IMU_GYRO_SENSOR} on site {IMU_SITE}",
    "imu.accelerometer": f"MuJoCo accelerometer sensor {IMU_ACC_SENSOR} on site {IMU_SITE} (specific force)",
    "lowcmd": "q = raw action * action_scale + default pose; dq = 0; tau = 0; kp, kd = simulator actuator gains",
    "odom": "simulator truth of the pelvis relative to the env origin; velocities in the pelvis frame",
    "sim.foot_contact": "env.sand.feet: granular + hard-floor force per foot (world), |F| > threshold, "
    "sinkage = max(0, -(sole site height above the sand surface))",
    "rate": "one sample per policy step (env.step_dt); no per-physics-substep samples",
}
"""Provenance of every recorded signal (stored in the run metadata as ``signal_sources``)."""


@dataclass
class RecordingCfg:
    """What :class:`EnvRecorder` writes."""

    env_index: int = 0
    """Env of the batch to record."""
    write_observation: bool = True
    """Write ``/policy/observation`` (the largest channel: 480 floats per step for a 5-frame history)."""
    write_odometry: bool = True
    """Write simulator-truth ``/odometry`` and ``/tf``."""
    write_sim_contact: bool = True
    """Write privileged ``/sim/foot_contact``."""
    overwrite: bool = False
    """Replace an existing output file (refused by default)."""


def joint_permutation(source_names: Sequence[str], target_names: Sequence[str] | None = None) -> np.ndarray:
    """Return ``perm`` with ``target_names[i] == source_names[perm[i]]`` (reorder by name).

    Args:
        source_names: Order of the arrays to reorder (e.g. mjlab's ``robot.joint_names``); a ``robot/`` prefix is
            ignored.
        target_names: Wanted order; the schema's canonical G1 order (``G1_JOINT_NAMES``) by default.

    Raises:
        ValueError: If a name is duplicated, missing or unknown.
    """
    if target_names is None:
        target_names = G1_JOINT_NAMES
    src = [n.split("/")[-1] for n in source_names]
    if len(set(src)) != len(src):
        raise ValueError(f"duplicated joint names in {src}")
    missing = [n for n in target_names if n not in src]
    unknown = [n for n in src if n not in target_names]
    if missing or unknown:
        raise ValueError(f"joint names do not match: missing {missing}, unknown {unknown}")
    index = {n: i for i, n in enumerate(src)}
    return np.array([index[n] for n in target_names], dtype=np.int64)


def _f32(x: torch.Tensor | np.ndarray) -> np.ndarray:
    """Return float64 values whose shortest repr is the float32 value's shortest repr (exact for float32)."""
    arr = x.detach().cpu().numpy() if isinstance(x, torch.Tensor) else np.asarray(x)
    if arr.dtype == np.float32:
        return arr.astype(str).astype(np.float64)
    return arr.astype(np.float64)


def policy_label(policy_path: str, onnx_meta: dict[str, str]) -> str:
    """Short policy name: the ONNX ``run_path`` metadata, else the policy file's directory name."""
    raw = onnx_meta.get("run_path") or Path(policy_path).resolve().parent.name or Path(policy_path).stem
    return re.sub(r"[^A-Za-z0-9_.@+-]+", "_", Path(raw).name)


def recording_file_name(label: str, material: str, speed: float) -> str:
    """File name of the recording of one (material, speed) evaluation cell."""
    return f"g1_{label}_{material}_v{speed:g}.mcap".replace("/", "_")


def _sha256(path: str) -> str:
    """Hex SHA-256 of a file."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def policy_run_metadata(
    *,
    policy_path: str,
    onnx_meta: dict[str, str],
    material: str,
    contact_model: str,
    terrain: str,
    control_rate_hz: float,
    label: str | None = None,
    notes: str = "",
    extra: dict[str, Any] | None = None,
) -> RunMetadata:
    """Run metadata of a policy rollout in the granular simulator (deterministic: no creation time).

    Args:
        policy_path: ONNX file that ran.
        onnx_meta: Its metadata properties (stored as JSON under ``policy_metadata``).
        material: Material preset (``gmloco.contact.MATERIAL_PRESETS`` name); its parameters go to ``extra``.
        contact_model: Foot contact model of the simulator.
        terrain: Sand terrain name.
        control_rate_hz: Policy (and logging) rate [Hz].
        label: Policy name in ``controller = "policy:<label>"``; :func:`policy_label` when None.
        notes: Free text (e.g. how far the policy is validated).
        extra: Further key/values (stringified, non-strings as JSON).
    """
    label = label or policy_label(policy_path, onnx_meta)
    digest = _sha256(policy_path)
    commit, dirty = git_commit(Path(__file__).parent)
    fields: dict[str, Any] = {
        "simulator": "mjlab 1.6 / MuJoCo Warp (gmloco.train granular G1 task)",
        "terrain": terrain,
        "policy_path": str(policy_path),
        "policy_sha256": digest,
        "policy_metadata": onnx_meta,
        "signal_sources": SIGNAL_SOURCES,
    }
    preset = gc.MATERIAL_PRESETS.get(material)
    if preset is not None and dataclasses.is_dataclass(preset):
        fields["material_params"] = dataclasses.asdict(preset)
    fields.update(extra or {})
    return RunMetadata(
        controller=f"policy:{label}",
        policy=f"{label} ({Path(policy_path).name}, sha256:{digest[:16]})",
        material=material,
        contact_model=contact_model,
        source="sim",
        commit=commit,
        commit_dirty=dirty,
        lowstate_rate_hz=control_rate_hz,
        control_rate_hz=control_rate_hz,
        support="none",
        notes=notes,
        extra={k: v if isinstance(v, str) else json.dumps(v) for k, v in fields.items()},
    )


class EnvRecorder:
    """Write env ``cfg.env_index`` of a granular mjlab env to one MCAP file (see the module docstring).

    Args:
        env: A ``ManagerBasedRlEnv`` of the granular G1 task (any number of envs).
        path: Output ``.mcap`` file.
        metadata: Run metadata (e.g. from :func:`policy_run_metadata`); its ``joint_names`` must be canonical.
        cfg: What to write.
    """

    def __init__(self, env: Any, path: str | Path, metadata: RunMetadata, cfg: RecordingCfg | None = None) -> None:
        from gmloco.train.sand import FOOT_SITES

        self.cfg = cfg or RecordingCfg()
        self.env = env
        k = self.cfg.env_index
        if not 0 <= k < env.num_envs:
            raise ValueError(f"env_index {k} out of range for {env.num_envs} envs")
        if tuple(metadata.joint_names) != tuple(G1_JOINT_NAMES):
            raise ValueError("metadata.joint_names must be the canonical G1 order (the recorder reorders by name)")
        if tuple(f.split("_")[0] for f in FOOT_SITES) != tuple(G1_FEET):
            raise ValueError(f"foot order {FOOT_SITES} differs from the schema's {G1_FEET}")
        self.k = k
        self.dt = float(env.step_dt)
        robot = env.scene["robot"]
        self.robot = robot
        self._joint_perm = torch.as_tensor(joint_permutation(robot.joint_names))
        self._act_perm = torch.as_tensor(joint_permutation(robot.actuator_names))
        self._ctrl_ids = robot.indexing.ctrl_ids.long().cpu()
        self._imu_site = robot.find_sites((IMU_SITE,), preserve_order=True)[0][0]
        self._gyro = env.scene[IMU_GYRO_SENSOR]
        self._acc = env.scene[IMU_ACC_SENSOR]
        self._action = env.action_manager.get_term(ACTION_TERM)
        self._target_perm = torch.as_tensor(joint_permutation(self._action.target_names))
        self._sand = getattr(env, "sand", None)
        topics = [TOPIC_JOINT_STATES, TOPIC_IMU, TOPIC_LOWCMD, TOPIC_COMMAND, TOPIC_POLICY_ACTION]
        topics += [TOPIC_POLICY_OBS] if self.cfg.write_observation else []
        topics += [TOPIC_ODOMETRY, TOPIC_TF] if self.cfg.write_odometry else []
        topics += [TOPIC_SIM_CONTACT] if self.cfg.write_sim_contact and self._sand is not None else []
        # Declare the channels with metadata first; the writer then declares the remaining required topics.
        wcfg = LogWriterCfg(topics=(TOPIC_JOINT_STATES, TOPIC_IMU, TOPIC_LOWCMD), overwrite=self.cfg.overwrite)
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.writer: G1LogWriter = G1LogWriter(self.path, metadata, wcfg)
        scale = self._action.scale
        scale_list = _f32(scale[k]).tolist() if isinstance(scale, torch.Tensor) else float(scale)
        self.writer.declare(TOPIC_POLICY_ACTION, joint_names=list(self._action.target_names), action_scale=scale_list)
        if self.cfg.write_observation:
            om = env.observation_manager
            terms = [
                [name, int(np.prod(dim))]
                for name, dim in zip(om.active_terms[OBS_GROUP], om.group_obs_term_dim[OBS_GROUP], strict=True)
            ]
            self.writer.declare(TOPIC_POLICY_OBS, terms=terms, group=OBS_GROUP)
        self._topics = set(topics)
        self._step = 0
        self.closed = False
        self.end_reason = ""

    @property
    def t(self) -> float:
        """Time of the current state [s] (policy steps since the recording started times ``step_dt``)."""
        return self._step * self.dt

    # -- state ----------------------------------------------------------------------------------------

    def _write_state(self, t: float) -> None:
        """Write LowState, IMU, odometry and contact truth of the current simulator state of env k."""
        k, d, jp = self.k, self.robot.data, self._joint_perm
        quat = _f32(d.site_quat_w[k, self._imu_site])
        self.writer.write_lowstate(
            t,
            _f32(d.joint_pos[k][jp]),
            _f32(d.joint_vel[k][jp]),
            _f32(d.qfrc_actuator[k][jp]),
            quat,
            _f32(self._gyro.data[k]),
            _f32(self._acc.data[k]),
            ddq=_f32(d.joint_acc[k][jp]),
            rpy=quat_to_rpy(quat),
            tick=round(t * 1000),
        )
        if TOPIC_ODOMETRY in self._topics:
            origin = self.env.scene.env_origins[k]
            self.writer.write_odometry(
                t,
                _f32(d.root_link_pos_w[k] - origin),
                _f32(d.root_link_quat_w[k]),
                _f32(d.root_link_lin_vel_b[k]),
                _f32(d.root_link_ang_vel_b[k]),
            )
        if TOPIC_SIM_CONTACT in self._topics:
            feet = self._sand.feet.update()  # type: ignore[union-attr]
            sinkage = torch.clamp(-feet.height[k], min=0.0)
            self.writer.write_sim_contact(t, feet.in_contact[k].cpu().numpy(), _f32(feet.force_w[k]), _f32(sinkage))

    def before_step(self, observation: np.ndarray | torch.Tensor, action: np.ndarray | torch.Tensor) -> None:
        """Record state x_i, the command, and the policy's observation and raw action of env k at t_i.

        Args:
            observation: Actor observation of env k ``[n_obs]`` or of all envs ``[W, n_obs]``.
            action: Raw action of env k ``[n_act]`` or of all envs ``[W, n_act]``.
        """
        if self.closed:
            return
        t = self.t
        self._write_state(t)
        cmd = _f32(self.env.command_manager.get_command(COMMAND_TERM)[self.k])
        self.writer.write_command(t, *cmd[:3].tolist())
        obs, act = _row(observation, self.k), _row(action, self.k)
        self.writer.write_policy(t, observation=obs if self.cfg.write_observation else None, action=act)

    def after_step(self, terminated: torch.Tensor | np.ndarray | None = None) -> None:
        """Record the LowCmd applied during the step just taken; close the file if env k terminated.

        Args:
            terminated: Termination flags of all envs ``[W]`` (``env.step``'s ``terminated``); a terminated env
                was reset by mjlab, so its recording ends at the last state before the fall.
        """
        if self.closed:
            return
        k, a = self.k, self._action
        tp = self._target_perm
        scale, offset = a.scale, a.offset
        raw = a.raw_action[k]
        scale_k = scale[k] if isinstance(scale, torch.Tensor) else scale
        offset_k = offset[k] if isinstance(offset, torch.Tensor) else offset
        q_cmd = (raw * scale_k + offset_k)[tp]
        model, ids, ap = self.env.sim.model, self._ctrl_ids, self._act_perm
        kp = model.actuator_gainprm[k if model.actuator_gainprm.shape[0] > 1 else 0][ids, 0][ap]
        kd = -model.actuator_biasprm[k if model.actuator_biasprm.shape[0] > 1 else 0][ids, 2][ap]
        zeros = np.zeros(len(tp))
        self.writer.write_lowcmd(self.t, _f32(q_cmd), zeros, _f32(kp), _f32(kd), zeros, sequence=self._step)
        self._step += 1
        if terminated is not None and _flag(terminated, k):
            msg = f"fell at t={self.t:.2f} s (termination; the env was reset, last state logged at t={self.t - self.dt:.2f} s)"
            self.writer.write_log(self.t, msg, "WARNING")
            self._finish(f"fell at t={self.t:.3f} s")

    def close(self, end_reason: str = "completed") -> Path:
        """Write the final state (unless the env terminated) and close the file; returns its path."""
        if not self.closed:
            self._write_state(self.t)
            self._finish(end_reason)
        return self.path

    def _finish(self, end_reason: str) -> None:
        """Close the writer with an end reason."""
        self.writer.close(end_reason, duration_s=f"{self.t:.3f}", env_index=str(self.k))
        self.closed = True
        self.end_reason = end_reason


def _row(x: np.ndarray | torch.Tensor, k: int) -> np.ndarray:
    """Row ``k`` of a batched ``[W, n]`` array, or the array itself when it is one env's ``[n]``, as float64."""
    arr = _f32(x)
    return arr[k] if arr.ndim >= 2 else arr


def _flag(x: np.ndarray | torch.Tensor, k: int) -> bool:
    """Element ``k`` of a per-env flag vector ``[W]``."""
    arr = x.detach().cpu().numpy() if isinstance(x, torch.Tensor) else np.asarray(x)
    return bool(arr[k])
