# SPDX-License-Identifier: Apache-2.0
"""Produce a recording: the G1 in MuJoCo C under the scripted stepping controller, written per the schema."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gmloco.deploy.logs.metadata import RunMetadata, git_commit
from gmloco.deploy.logs.schema import (
    TOPIC_COMMAND,
    TOPIC_IMU,
    TOPIC_JOINT_STATES,
    TOPIC_LOWCMD,
    TOPIC_ODOMETRY,
    TOPIC_SIM_CONTACT,
    TOPIC_TF,
)
from gmloco.deploy.logs.sim.ground import RigidGround, RigidGroundCfg
from gmloco.deploy.logs.sim.recorder import MujocoG1Recorder
from gmloco.deploy.logs.sim.scene import G1SceneCfg, build_g1_model, g1_effort_limits
from gmloco.deploy.logs.sim.scripted import ScriptedStepping, ScriptedSteppingCfg
from gmloco.deploy.logs.sim.support import VirtualGantry, VirtualGantryCfg
from gmloco.deploy.logs.writer import G1LogWriter, LogWriterCfg

__all__ = ["CommandSegment", "ScriptedRunCfg", "record_scripted_run"]


@dataclass(frozen=True)
class CommandSegment:
    """A velocity command that holds from ``t_start`` until the next segment."""

    t_start: float
    """Start time [s]."""
    lin_vel_x: float
    """Forward speed command [m/s]."""
    lin_vel_y: float = 0.0
    """Lateral speed command [m/s] (logged; the scripted gait ignores it)."""
    ang_vel_z: float = 0.0
    """Yaw-rate command [rad/s] (logged; the scripted gait ignores it)."""


@dataclass
class ScriptedRunCfg:
    """One scripted recording."""

    duration: float = 10.0
    """Simulated time [s]."""
    commands: tuple[CommandSegment, ...] = (CommandSegment(0.0, 0.0),)
    """Velocity command schedule."""
    lowstate_rate_hz: float = 100.0
    """Rate of LowState/LowCmd messages [Hz] (500 on the robot; lower keeps sample files small)."""
    control_rate_hz: float = 50.0
    """Controller update rate [Hz] (target and command messages)."""
    write_odometry: bool = True
    """Log ground-truth base odometry (off = a robot without a base estimator)."""
    write_sim_contact: bool = True
    """Log privileged foot contact truth."""
    fall_height: float = 0.45
    """Stop when the pelvis drops below this height [m]; the end record says ``fell``."""
    scene: G1SceneCfg = field(default_factory=G1SceneCfg)
    """MuJoCo scene."""
    controller: ScriptedSteppingCfg = field(default_factory=ScriptedSteppingCfg)
    """Scripted controller."""
    gantry: VirtualGantryCfg = field(default_factory=VirtualGantryCfg)
    """Virtual gantry (recorded in the metadata)."""
    ground: RigidGroundCfg = field(default_factory=RigidGroundCfg)
    """Ground contact (rigid until a granular model is plugged in)."""
    notes: str = ""
    """Free text for the metadata."""


def _command_at(cmds: tuple[CommandSegment, ...], t: float) -> CommandSegment:
    """Return the command segment active at time ``t``."""
    active = [c for c in cmds if c.t_start <= t]
    return active[-1] if active else cmds[0]


def _metadata(cfg: ScriptedRunCfg, ground: RigidGround) -> RunMetadata:
    """Run metadata of a scripted recording (deterministic: no creation time)."""
    commit, dirty = git_commit(Path(__file__).parent)
    c = cfg.controller
    return RunMetadata(
        controller="scripted_stepping",
        policy="none",
        material=ground.material,
        contact_model=ground.contact_model,
        source="sim",
        commit=commit,
        commit_dirty=dirty,
        lowstate_rate_hz=cfg.lowstate_rate_hz,
        control_rate_hz=cfg.control_rate_hz,
        support=cfg.gantry.label(),
        notes=cfg.notes or "MuJoCo C G1 (mjlab MJCF), scripted stepping controller; not a policy.",
        extra={
            "simulator": "mujoco-c",
            "physics_dt": str(cfg.scene.timestep),
            "gait_period_s": str(c.period),
            "swing_fraction": str(c.swing_fraction),
            "commands": repr([(s.t_start, s.lin_vel_x) for s in cfg.commands]),
        },
    )


def record_scripted_run(path: str | Path, cfg: ScriptedRunCfg | None = None, overwrite: bool = False) -> Path:
    """Simulate the scripted G1 and write the recording.

    Args:
        path: Output ``.mcap`` file (refused if it exists, unless ``overwrite``).
        cfg: Recording settings.
        overwrite: Replace an existing output file.

    Returns:
        The path written.
    """
    import mujoco

    cfg = cfg or ScriptedRunCfg()
    model = build_g1_model(cfg.scene)
    data = mujoco.MjData(model)
    ctrl = ScriptedStepping(cfg.controller)
    ground, gantry = RigidGround(cfg.ground, model), VirtualGantry(cfg.gantry, model)
    dt = model.opt.timestep
    log_every = max(1, round(1.0 / (cfg.lowstate_rate_hz * dt)))
    ctrl_every = max(1, round(1.0 / (cfg.control_rate_hz * dt)))
    limits = g1_effort_limits()
    topics = [TOPIC_JOINT_STATES, TOPIC_IMU, TOPIC_LOWCMD, TOPIC_COMMAND]
    topics += [TOPIC_ODOMETRY, TOPIC_TF] if cfg.write_odometry else []
    topics += [TOPIC_SIM_CONTACT] if cfg.write_sim_contact else []
    wcfg = LogWriterCfg(topics=tuple(topics), overwrite=overwrite)
    # Start standing on the floor: pelvis height of mjlab's knees-bent keyframe.
    data.qpos[2], data.qpos[3], data.qpos[7:] = 0.76, 1.0, cfg.controller.default_pose
    end_reason = "completed"
    with G1LogWriter(path, _metadata(cfg, ground), wcfg) as w:
        rec = MujocoG1Recorder(w, model, ground)
        q_target, cmd = cfg.controller.default_pose.copy(), cfg.commands[0]
        zeros = np.zeros_like(q_target)
        for k in range(round(cfg.duration / dt)):
            t = k * dt
            mujoco.mj_step1(model, data)
            snap = rec.snapshot(data)
            if k % ctrl_every == 0:
                cmd = _command_at(cfg.commands, t)
                q_target = ctrl.targets(t, snap.base_quat, snap.gyro, cmd.lin_vel_x)
                w.write_command(t, cmd.lin_vel_x, cmd.lin_vel_y, cmd.ang_vel_z)
            # Motor-level PD, as the G1's motor drivers run it on LowCmd (dq target 0, no feed-forward).
            tau = np.clip(ctrl.cfg.kp * (q_target - snap.q) - ctrl.cfg.kd * snap.dq, -limits, limits)
            data.qfrc_applied[6:] = tau
            ground.apply(model, data)
            gantry.apply(data)
            mujoco.mj_step2(model, data)
            if k % log_every == 0:
                rec.record_lowstate(t, snap, data, tau)
                w.write_lowcmd(t, q_target, zeros, ctrl.cfg.kp, ctrl.cfg.kd, zeros)
                if cfg.write_odometry:
                    rec.record_odometry(t, snap)
                if cfg.write_sim_contact:
                    rec.record_contact(t, data)
            if snap.base_pos[2] < cfg.fall_height:
                end_reason = f"fell at t={t:.3f} s"
                w.write_log(t, f"pelvis below {cfg.fall_height} m: robot fell, recording stopped", "WARNING")
                break
        w.close(end_reason)
    return Path(path)
