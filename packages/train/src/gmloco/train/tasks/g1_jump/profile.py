# SPDX-License-Identifier: Apache-2.0
"""Centre-of-mass and foot keyframe profiles of a two-footed jump (pure numpy, no robot model).

The jump is cut into phases: stand, crouch, push-off, flight, landing, recover, stand. The vertical CoM
height is a quintic per phase whose boundary conditions make position, velocity and acceleration continuous,
so the ground reaction ``F_z = m (z'' + g)`` is continuous and falls to zero exactly at take-off and rises from
zero at touch-down. In flight the CoM is ballistic: ``z'' = -g``, ``x'' = 0``. The horizontal push and braking
forces are proportional to the vertical one (``x'' = k (z'' + g)``), so the force direction, and hence the
friction ratio ``|F_x| / F_z = |k|``, is constant through each stance phase.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["GRAVITY", "JumpProfile", "JumpProfileCfg", "make_jump_profile", "min_jerk", "quintic"]

GRAVITY = 9.81
"""Gravitational acceleration [m/s^2] (MuJoCo's default model value)."""


@dataclass
class JumpProfileCfg:
    """Timing and geometry of one jump (all heights relative to the standing CoM height)."""

    name: str = "vertical"
    """Motion name, used for file names and logs."""
    distance: float = 0.0
    """Forward jump distance of the feet and of the standing CoM [m]; 0 is a vertical jump."""
    apex_rise: float = 0.08
    """Rise of the CoM apex above its take-off height [m]; sets the take-off speed sqrt(2 g h)."""
    crouch_depth: float = 0.15
    """How far the CoM is lowered before the push-off [m]."""
    landing_depth: float = 0.12
    """How far below the standing height the CoM comes to rest after the landing [m]."""
    takeoff_rise: float = -0.04
    """CoM height at take-off and at touch-down above the standing height [m]; below zero, because the legs of
    the standing pose are almost straight and must still reach the ground while the CoM rises after take-off."""
    foot_lift: float = 0.05
    """Peak height of the soles above the ground in flight [m]."""
    foot_lift_fraction: float = 0.35
    """Fraction of the flight over which the soles rise (and, at its end, are lowered) [-]; at most 0.5."""
    crouch_shift: float = 0.0
    """Forward CoM shift over the feet during the crouch, undone during the recovery [m]; a forward jump leans
    into the push so that the ground force through the CoM meets the ground under the soles."""
    t_stand: float = 0.30
    """Standing time before the crouch and after the recovery [s]."""
    t_crouch: float = 0.50
    """Duration of the crouch [s]."""
    t_push: float = 0.22
    """Duration of the push-off (crouch to take-off) [s]."""
    t_land: float = 0.30
    """Duration of the landing (touch-down to rest in the landing crouch) [s]."""
    t_recover: float = 0.60
    """Duration of the rise from the landing crouch back to standing [s]."""
    fps: float = 100.0
    """Sample rate of the profile [Hz]."""


@dataclass
class JumpProfile:
    """Sampled CoM and foot targets of a jump; arrays are [T] or [T, 3] with T samples at ``1 / fps``."""

    time: np.ndarray
    """Sample times [s], shape [T]."""
    com: np.ndarray
    """CoM position relative to the standing CoM at t = 0 [m], shape [T, 3]."""
    com_vel: np.ndarray
    """CoM velocity [m/s], shape [T, 3]."""
    com_acc: np.ndarray
    """CoM acceleration [m/s^2], shape [T, 3]."""
    foot_offset: np.ndarray
    """Displacement of both feet from their standing position [m], shape [T, 3]."""
    in_contact: np.ndarray
    """Whether the feet are on the ground, shape [T] (bool)."""
    lean_fraction: np.ndarray
    """Fraction of the full forward lean of the pelvis [-], shape [T]: min-jerk up over the crouch, held through
    push-off, flight and landing, min-jerk down over the recovery."""
    t_takeoff: float
    """Take-off time [s]."""
    t_touchdown: float
    """Touch-down time [s]."""
    t_push_start: float
    """Start of the push-off [s]."""


def quintic(
    t: np.ndarray, duration: float, start: tuple[float, float, float], end: tuple[float, float, float]
) -> np.ndarray:
    """Evaluate the quintic with (position, velocity, acceleration) ``start`` at 0 and ``end`` at ``duration``.

    Returns:
        Position, velocity and acceleration, shape [3, len(t)].
    """
    T = duration
    A = np.array(
        [
            [1, 0, 0, 0, 0, 0],
            [0, 1, 0, 0, 0, 0],
            [0, 0, 2, 0, 0, 0],
            [1, T, T**2, T**3, T**4, T**5],
            [0, 1, 2 * T, 3 * T**2, 4 * T**3, 5 * T**4],
            [0, 0, 2, 6 * T, 12 * T**2, 20 * T**3],
        ]
    )
    c = np.linalg.solve(A, np.array([*start, *end], dtype=np.float64))
    powers = np.stack([t**i for i in range(6)])
    pos = c @ powers
    vel = np.array([i * c[i] for i in range(1, 6)]) @ np.stack([t ** (i - 1) for i in range(1, 6)])
    acc = np.array([i * (i - 1) * c[i] for i in range(2, 6)]) @ np.stack([t ** (i - 2) for i in range(2, 6)])
    return np.stack([pos, vel, acc])


def min_jerk(s: np.ndarray) -> np.ndarray:
    """Minimum-jerk blend 10 s^3 - 15 s^4 + 6 s^5 of s in [0, 1]."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10.0 - 15.0 * s + 6.0 * s**2)


def _vertical(cfg: JumpProfileCfg, t: np.ndarray, times: dict[str, float]) -> np.ndarray:
    """CoM height (z, z', z'') relative to standing, shape [3, T]."""
    g, v0 = GRAVITY, math.sqrt(2.0 * GRAVITY * cfg.apex_rise)
    h_to, t_flight = cfg.takeoff_rise, 2.0 * v0 / GRAVITY
    out = np.zeros((3, t.size))
    pieces = [
        ("crouch", cfg.t_crouch, (0.0, 0.0, 0.0), (-cfg.crouch_depth, 0.0, 0.0)),
        ("push", cfg.t_push, (-cfg.crouch_depth, 0.0, 0.0), (h_to, v0, -g)),
        ("land", cfg.t_land, (h_to, -v0, -g), (-cfg.landing_depth, 0.0, 0.0)),
        ("recover", cfg.t_recover, (-cfg.landing_depth, 0.0, 0.0), (0.0, 0.0, 0.0)),
    ]
    for name, duration, start, end in pieces:
        mask = (t >= times[name]) & (t < times[name] + duration)
        out[:, mask] = quintic(t[mask] - times[name], duration, start, end)
    fly = (t >= times["flight"]) & (t < times["flight"] + t_flight)
    tau = t[fly] - times["flight"]
    # Ballistic flight: z = h_to + v0 tau - g tau^2 / 2.
    out[:, fly] = np.stack([h_to + v0 * tau - 0.5 * g * tau**2, v0 - g * tau, np.full_like(tau, -g)])
    after = t >= times["recover"] + cfg.t_recover
    out[:, after] = 0.0
    return out


def _horizontal(cfg: JumpProfileCfg, t: np.ndarray, z_acc: np.ndarray, times: dict[str, float]) -> np.ndarray:
    """CoM x (x, x', x'') with the stance forces parallel to a fixed direction, shape [3, T]."""
    dt = t[1] - t[0]
    push = (t >= times["push"]) & (t < times["flight"])
    land = (t >= times["land"]) & (t < times["recover"])
    support = z_acc + GRAVITY  # F_z / m, zero at take-off and touch-down

    def _travel(k_push: float, k_land: float) -> np.ndarray:
        """Integrate x'' = k (z'' + g) in stance (trapezoid rule), x'' = 0 elsewhere."""
        acc = np.where(push, k_push * support, 0.0) + np.where(land, -k_land * support, 0.0)
        vel = np.concatenate([[0.0], np.cumsum(0.5 * (acc[1:] + acc[:-1]) * dt)])
        pos = np.concatenate([[0.0], np.cumsum(0.5 * (vel[1:] + vel[:-1]) * dt)])
        return np.stack([pos, vel, acc])

    shift = np.zeros((3, t.size))
    for name, duration, start, end in (
        ("crouch", cfg.t_crouch, 0.0, cfg.crouch_shift),
        ("recover", cfg.t_recover, cfg.crouch_shift, 0.0),
    ):
        mask = (t >= times[name]) & (t < times[name] + duration)
        shift[:, mask] = quintic(t[mask] - times[name], duration, (start, 0.0, 0.0), (end, 0.0, 0.0))
    between = (t >= times["push"]) & (t < times["recover"])
    shift[0, between] = cfg.crouch_shift
    if cfg.distance == 0.0:
        return shift
    # Unit take-off speed: the push gains 1 m/s, the landing removes it; the travel is linear in the speed.
    k_push = 1.0 / (np.sum(support[push]) * dt)
    k_land = 1.0 / (np.sum(support[land]) * dt)
    unit = _travel(k_push, k_land)
    speed = cfg.distance / unit[0, -1]
    return _travel(speed * k_push, speed * k_land) + shift


def _feet(cfg: JumpProfileCfg, t: np.ndarray, times: dict[str, float]) -> np.ndarray:
    """Foot displacement in flight: min-jerk forward, min-jerk lift and lowering, shape [T, 3].

    The soles leave and meet the ground at rest (zero velocity and acceleration), so the joint accelerations stay
    finite; the lift takes only the first ``foot_lift_fraction`` of the flight because the legs are almost
    straight at take-off and the CoM keeps rising at the take-off speed.
    """
    t_flight = times["land"] - times["flight"]
    s = np.clip((t - times["flight"]) / t_flight, 0.0, 1.0)
    r = cfg.foot_lift_fraction
    offset = np.zeros((t.size, 3))
    offset[:, 0] = cfg.distance * min_jerk(s)
    offset[:, 2] = cfg.foot_lift * (min_jerk(s / r) - min_jerk((s - 1.0 + r) / r))
    return offset


def make_jump_profile(cfg: JumpProfileCfg) -> JumpProfile:
    """Sample the CoM and foot targets of the jump described by ``cfg``."""
    if cfg.apex_rise <= 0.0 or cfg.fps <= 0.0 or cfg.crouch_depth <= 0.0:
        raise ValueError(f"apex_rise, fps and crouch_depth must be positive, got {cfg}")
    if not 0.0 < cfg.foot_lift_fraction <= 0.5:
        raise ValueError(f"foot_lift_fraction must lie in (0, 0.5], got {cfg.foot_lift_fraction}")
    t_flight = 2.0 * math.sqrt(2.0 * GRAVITY * cfg.apex_rise) / GRAVITY
    times: dict[str, float] = {"crouch": cfg.t_stand}
    times["push"] = times["crouch"] + cfg.t_crouch
    times["flight"] = times["push"] + cfg.t_push
    times["land"] = times["flight"] + t_flight
    times["recover"] = times["land"] + cfg.t_land
    total = times["recover"] + cfg.t_recover + cfg.t_stand
    t = np.arange(round(total * cfg.fps) + 1) / cfg.fps
    z = _vertical(cfg, t, times)
    x = _horizontal(cfg, t, z[2], times)
    zero = np.zeros((3, t.size))
    com = np.stack([x, zero, z], axis=-1)  # [3 (pos, vel, acc), T, 3 (xyz)]
    return JumpProfile(
        time=t,
        com=com[0],
        com_vel=com[1],
        com_acc=com[2],
        foot_offset=_feet(cfg, t, times),
        in_contact=(t < times["flight"]) | (t >= times["land"]),
        lean_fraction=min_jerk((t - times["crouch"]) / cfg.t_crouch) - min_jerk((t - times["recover"]) / cfg.t_recover),
        t_takeoff=times["flight"],
        t_touchdown=times["land"],
        t_push_start=times["push"],
    )
