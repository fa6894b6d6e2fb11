# SPDX-License-Identifier: Apache-2.0
"""Sole-scale calibration experiments: a kinematic G1 sole driven through press, tilt, drag, lift-off, repeat, twist.

The probes (:data:`PROBE_EXPERIMENTS`) press the sole again after a slide or a turn.

Every experiment is a list of phases; each frame a phase turns the sole's pose and the sand force of the previous
frame into the sole's velocity (force feedback only in ``press``: the load ramps until the vertical sand force
reaches its target, e.g. the single-stance G1 weight). The same controller drives any sand: Newton MPM
(:mod:`gmloco.eval.calibration.mpm_sand`) or the float64 3D-RFT reference (:mod:`gmloco.eval.calibration.rft_sand`),
so the recorded kinematics replay exactly through the contact model that is fitted to them. Each frame the sand
returns its wrench on the sole: the force and the torque about the sole-box centre, both recorded.

``twist`` probes the resistance of loaded sand to a sole turning about the vertical (the yaw torque that sets how
far a walking policy's heading drifts): the sole is pressed to the single-stance load, held, then turned about the
world z axis through its centre by +``twist_angle``, -2 ``twist_angle``, +``twist_angle`` at ``twist_rate``, at the
load's depth. A GPU MPM run of it alone (``<folder>/basalt.npz`` then holds the twist record only)::

    python -m gmloco.eval.calibration --material basalt --experiments twist --device cuda:0 --out <folder>

and without ``--experiments`` every experiment, twist included, is recorded.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

__all__ = [
    "EXPERIMENTS",
    "G1_MASS",
    "PROBE_EXPERIMENTS",
    "PhaseCfg",
    "SoleProtocolCfg",
    "SoleRecord",
    "SoleSand",
    "experiment_phases",
    "rotation_y",
    "rotation_z",
    "run_experiment",
]

G1_MASS = 35.0
"""G1 mass [kg] (``BoxCfg.mass``; the MPM scene reads the model's own); single-stance load = G1_MASS g."""
GRAVITY = 9.81
"""Gravitational acceleration [m/s^2]."""
EXPERIMENTS: tuple[str, ...] = ("press", "press_fast", "tilt", "drag", "drag_fast", "liftoff", "repeat", "twist")
"""Experiment names, in dataset order (``_fast``: 4x the press / drag speed, for rate dependence)."""
PROBE_EXPERIMENTS: tuple[str, ...] = ("slide_repress", "twist_repress")
"""Experiments outside the default set, recorded into datasets of their own (adding them to :data:`EXPERIMENTS`
would redraw the fit / held-out split of every dataset): the sole pressed to the single-stance load slides 5 cm at
``drag_speed`` (or turns +``twist_angle`` about the vertical) at constant depth, rests, and is pressed again until
the sand carries the load. The extra depth that takes is what a slip or a turn costs a stance foot."""

PhaseKind = Literal["press", "hold", "move", "pitch", "yaw"]


@dataclass(frozen=True)
class PhaseCfg:
    """One phase of a sole experiment."""

    kind: PhaseKind
    """``press``: descend at ``speed`` until F_z >= ``load`` (or ``duration``); ``hold``: rest; ``move``: constant
    ``velocity``; ``pitch``: rotate about the world y axis at ``rate`` through the sole centre; ``yaw``: rotate about
    the world z axis (the vertical) at ``rate`` through the sole centre, the centre staying where it is."""
    duration: float
    """Phase length [s] (a press ends earlier once its load is reached)."""
    load: float = 0.0
    """Target vertical sand force of a press [N]."""
    speed: float = 0.0
    """Descent speed of a press [m/s]."""
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    """Linear velocity of a move [m/s]."""
    rate: float = 0.0
    """Rotation rate of a pitch or yaw [rad/s] (signed: positive turns counter-clockwise about +y or +z)."""


@dataclass(frozen=True)
class SoleProtocolCfg:
    """Sole geometry, loads, speeds and the frame time of the calibration experiments."""

    sole_size: tuple[float, float, float] = (0.206, 0.0736, 0.03539)
    """G1 foot box (length x, width y, height z) [m] (``gmloco.contact.g1_foot_box_cfg``)."""
    robot_mass: float = G1_MASS
    """Robot mass whose weight is the single-stance load [kg]."""
    press_speed: float = 0.05
    """Descent speed while loading [m/s] (quasi-static: rho v^2 << RFT stress)."""
    drag_speed: float = 0.1
    """Horizontal drag speed [m/s]."""
    lift_speed: float = 0.1
    """Lift-off speed [m/s]."""
    tilt_rate: float = 1.0
    """Pitch rate of the tilt experiment [rad/s]."""
    tilt_angle: float = 0.26
    """Pitch amplitude of the tilt experiment [rad] (~15 deg)."""
    twist_rate: float = 1.0
    """Yaw rate of the twist experiment [rad/s] (> 0; the sole turns +, -, + at this speed)."""
    twist_angle: float = 0.26
    """Yaw amplitude of the twist experiment [rad] (> 0; ~15 deg)."""
    hold_time: float = 0.2
    """Rest at load before the next phase [s]."""
    max_press_time: float = 3.0
    """Longest press [s] (a medium that cannot carry the load stops here; the record shows it)."""
    start_gap: float = 0.005
    """Sole height above the surface at the start [m]."""
    repeats: int = 3
    """Steps into one footprint in ``repeat``."""
    frame_dt: float = 0.01
    """Frame time = recording period [s] (the MPM step)."""
    time_scale: float = 1.0
    """Factor on every phase duration (<1 for CPU smoke runs; the record keeps its own time axis)."""

    def __post_init__(self) -> None:
        """Raise ValueError on a twist that does not turn (non-positive rate or angle)."""
        if not self.twist_rate > 0.0:
            raise ValueError(f"twist_rate must be > 0 rad/s (the sign alternates within the experiment), "
                             f"got {self.twist_rate}")  # fmt: skip
        if not self.twist_angle > 0.0:
            raise ValueError(f"twist_angle must be > 0 rad, got {self.twist_angle}")

    @property
    def weight(self) -> float:
        """Single-stance load [N]."""
        return self.robot_mass * GRAVITY


def experiment_phases(name: str, cfg: SoleProtocolCfg) -> list[PhaseCfg]:
    """Return the phases of experiment ``name`` (one of :data:`EXPERIMENTS`)."""
    if name.endswith("_fast"):
        fast = replace(cfg, press_speed=4 * cfg.press_speed, drag_speed=4 * cfg.drag_speed)
        return [replace(p, duration=p.duration / 4) if p.kind == "move" else p
                for p in experiment_phases(name.removesuffix("_fast"), fast)]  # fmt: skip
    w, s = cfg.weight, cfg.time_scale
    press = PhaseCfg("press", cfg.max_press_time * s, load=w, speed=cfg.press_speed)
    half = PhaseCfg("press", cfg.max_press_time * s, load=0.5 * w, speed=cfg.press_speed)
    hold = PhaseCfg("hold", cfg.hold_time * s)
    lift = PhaseCfg("move", 0.6 * s, velocity=(0.0, 0.0, cfg.lift_speed))
    turn = cfg.tilt_angle / cfg.tilt_rate * s
    yaw = cfg.twist_angle / cfg.twist_rate * s
    table: dict[str, list[PhaseCfg]] = {
        "press": [press, hold],
        "tilt": [half, hold, *_swing("pitch", turn, cfg.tilt_rate)],
        "drag": [half, hold, PhaseCfg("move", 1.0 * s, velocity=(cfg.drag_speed, 0.0, 0.0)), hold],
        "liftoff": [press, hold, lift],
        "repeat": [p for _ in range(cfg.repeats) for p in (press, hold, lift)],
        "twist": [press, hold, *_swing("yaw", yaw, cfg.twist_rate)],
        "slide_repress": [press, hold, PhaseCfg("move", 0.5 * s, velocity=(cfg.drag_speed, 0.0, 0.0)), hold, press,
                          hold],
        "twist_repress": [press, hold, PhaseCfg("yaw", yaw, rate=cfg.twist_rate), hold, press, hold],
    }  # fmt: skip
    if name not in table:
        raise ValueError(f"unknown experiment {name!r}: choose from {EXPERIMENTS + PROBE_EXPERIMENTS}")
    return table[name]


def _swing(kind: PhaseKind, duration: float, rate: float) -> list[PhaseCfg]:
    """Turn by ``rate * duration``, back twice as far, and forward again to the start (``pitch`` or ``yaw``)."""
    return [
        PhaseCfg(kind, duration, rate=rate),
        PhaseCfg(kind, 2 * duration, rate=-rate),
        PhaseCfg(kind, duration, rate=rate),
    ]


@dataclass
class SoleRecord:
    """One experiment's time series (sole-frame origin at the sole-box centre)."""

    time: np.ndarray
    """Frame start times [s], [T]."""
    pos: np.ndarray
    """Sole-box centre [m], [T, 3]."""
    rot: np.ndarray
    """Sole rotation body -> world, [T, 3, 3]."""
    lin_vel: np.ndarray
    """Linear velocity of the centre [m/s], [T, 3]."""
    ang_vel: np.ndarray
    """Angular velocity [rad/s], [T, 3]."""
    force: np.ndarray
    """Force of the sand on the sole [N], [T, 3]."""
    depth: np.ndarray
    """Depth of the sole's lowest point below the undisturbed surface z = 0 [m], [T]."""
    phase: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    """Phase index of each frame, [T]."""
    torque: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    """Torque of the sand on the sole about the sole-box centre, world axes [N m], [T, 3]; ``torque[:, 2]`` is the
    yaw torque. Empty ([0, 3]) for records whose sand reported forces only (a dataset file without torques)."""

    @property
    def has_torque(self) -> bool:
        """Whether the record carries a torque for every frame."""
        return self.torque.shape == (len(self.time), 3) and len(self.time) > 0


def rotation_y(angle: float) -> np.ndarray:
    """Return the rotation about world y by ``angle`` [rad], [3, 3]."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rotation_z(angle: float) -> np.ndarray:
    """Return the rotation about world z by ``angle`` [rad], [3, 3]."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


SoleSand = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
"""One frame of a sand: (pos [3], rot [3, 3], lin_vel [3], ang_vel [3]) -> wrench of the sand on the sole [6]:
force [N] (world axes) then torque about the sole-box centre ``pos`` [N m] (world axes); stateful."""


def _lowest_point(pos: np.ndarray, rot: np.ndarray, half: np.ndarray) -> float:
    """Return the lowest z of the box [m]."""
    return float(pos[2] - np.abs(rot[2]) @ half)


def run_experiment(name: str, cfg: SoleProtocolCfg, sand: SoleSand) -> SoleRecord:
    """Drive a fresh sand through experiment ``name``; the sole starts ``start_gap`` above z = 0.

    Each frame: the phase picks the velocity from the pose and the previous frame's force, the sand returns this
    frame's wrench at the pose and velocity, then the pose advances by one frame. The orientation is the pitch about
    world y followed by the yaw about world z (``rotation_z(yaw) @ rotation_y(pitch)``); no experiment pitches and
    yaws at once, so each phase's angular velocity is its rate about its own world axis.
    """
    half = 0.5 * np.asarray(cfg.sole_size)
    pos = np.array([0.0, 0.0, half[2] + cfg.start_gap])
    angle, yaw, force = 0.0, 0.0, np.zeros(3)
    rows: list[tuple] = []
    t = 0.0
    for k, phase in enumerate(experiment_phases(name, cfg)):
        for _ in range(max(1, round(phase.duration / cfg.frame_dt))):
            if phase.kind == "press" and force[2] >= phase.load:
                break
            lin, ang = np.zeros(3), np.zeros(3)
            if phase.kind == "press":
                lin[2] = -phase.speed
            elif phase.kind == "move":
                lin[:] = phase.velocity
            elif phase.kind == "pitch":
                ang[1] = phase.rate
            elif phase.kind == "yaw":
                ang[2] = phase.rate
            rot = rotation_y(angle) if yaw == 0.0 else rotation_z(yaw) @ rotation_y(angle)
            wrench = np.asarray(sand(pos, rot, lin, ang), dtype=np.float64)
            if wrench.shape != (6,):
                raise ValueError(f"a sole sand returns its wrench (force, torque) [6], got shape {wrench.shape}")
            force = wrench[:3]
            rows.append((t, pos.copy(), rot, lin, ang, force, -_lowest_point(pos, rot, half), k, wrench[3:]))
            pos = pos + lin * cfg.frame_dt
            angle += ang[1] * cfg.frame_dt
            yaw += ang[2] * cfg.frame_dt
            t += cfg.frame_dt
    cols = list(zip(*rows, strict=True))
    return SoleRecord(*(np.array(c) for c in cols[:7]), phase=np.array(cols[7], dtype=np.int64),
                      torque=np.array(cols[8]))  # fmt: skip
