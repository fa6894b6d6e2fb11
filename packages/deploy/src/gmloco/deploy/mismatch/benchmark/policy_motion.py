# SPDX-License-Identifier: Apache-2.0
"""A trained walking policy (exported ONNX, onnxruntime on CPU) as the truth robot's controller.

The policy sees what a deployed policy sees: the *measured* encoders and IMU (offsets, noise and mounting
rotation included), the velocity command and its last action; it runs at its ``policy_dt`` and holds its
joint targets in between. The observation layout is the one of the exported metadata (mjlab's observation
manager: terms in ``observation_names`` order, each term's history oldest first, flattened).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gmloco.deploy.logs.g1 import G1_JOINT_NAMES

__all__ = [
    "COMPOSITE_SCHEDULE",
    "MOTIONS",
    "TURN_SCHEDULE",
    "WALK_SPEEDS_SCHEDULE",
    "PolicyMotion",
    "PolicyMotionCfg",
    "motion_cfg",
]

Segment = tuple[float, float, float, float]
"""One command-schedule segment: (start time [s], forward speed [m/s], lateral speed [m/s], yaw rate [rad/s])."""

COMPOSITE_SCHEDULE: tuple[Segment, ...] = (
    (0.0, 0.0, 0.0, 0.0),
    (3.0, 0.5, 0.0, 0.0),
    (7.0, 1.0, 0.0, 0.0),
    (11.0, 1.5, 0.0, 0.0),
    (14.0, 0.8, 0.0, 0.5),
)
"""The composite motion: stand 3 s, walk at 0.5, 1.0 and 1.5 m/s, then a 0.5 rad/s left turn at 0.8 m/s (to the
end of the recording; 18 s in all). Within the policy's training ranges (forward up to 1.7 m/s and yaw rate up to
0.7 rad/s from the second command stage on)."""


@dataclass
class PolicyMotionCfg:
    """The walking-policy motion of a benchmark episode."""

    path: str = "artifacts/ppo_rft3d/policy.onnx"
    """Exported policy (``gmloco.train`` export metadata: gains, default pose, history, action scale)."""
    speed: float = 1.0
    """Commanded forward speed [m/s] (when ``schedule`` is None)."""
    stand_time: float = 0.5
    """Zero command before walking [s] (when ``schedule`` is None)."""
    schedule: tuple[Segment, ...] | None = None
    """Piecewise-constant command schedule, segments sorted by start time, the first at 0 s; each holds until the
    next starts (the last to the end). None: zero for ``stand_time``, then ``speed`` forward."""

    def command(self, t: float) -> np.ndarray:
        """Velocity command (forward [m/s], lateral [m/s], yaw rate [rad/s]) at time ``t`` [s], shape [3]."""
        if self.schedule is None:
            return np.array([self.speed if t >= self.stand_time else 0.0, 0.0, 0.0])
        cur = self.schedule[0]
        for seg in self.schedule:
            if t + 1e-9 >= seg[0]:
                cur = seg
        return np.array(cur[1:], float)


WALK_SPEEDS_SCHEDULE: tuple[Segment, ...] = (
    (0.0, 0.0, 0.0, 0.0),
    (1.0, 0.5, 0.0, 0.0),
    (4.0, 1.0, 0.0, 0.0),
    (7.0, 1.5, 0.0, 0.0),
)
"""The protocol's walking stage: stand 1 s, then 3 s each at 0.5, 1.0 and 1.5 m/s (10 s in all)."""

TURN_SCHEDULE: tuple[Segment, ...] = (
    (0.0, 0.0, 0.0, 0.0),
    (1.0, 0.8, 0.0, 0.0),
    (2.0, 0.8, 0.0, 0.5),
    (5.0, 0.8, 0.0, -0.5),
)
"""The protocol's turning stage: stand 1 s, walk 1 s at 0.8 m/s, then turn left and right at 0.5 rad/s, 3 s each
(8 s in all)."""

MOTIONS: dict[str, float] = {"walk": 8.0, "composite": 18.0, "walk_speeds": 10.0, "turn": 8.0}
"""Named sand-suite motions and their recording lengths [s]: ``walk`` (1 m/s after 0.5 s standing, the suite's
motion through v3) and ``composite`` (:data:`COMPOSITE_SCHEDULE`)."""


def motion_cfg(name: str = "walk") -> PolicyMotionCfg:
    """The policy motion called ``name`` (a key of :data:`MOTIONS`)."""
    if name == "walk":
        return PolicyMotionCfg()
    if name == "composite":
        return PolicyMotionCfg(schedule=COMPOSITE_SCHEDULE)
    if name == "walk_speeds":
        return PolicyMotionCfg(schedule=WALK_SPEEDS_SCHEDULE)
    if name == "turn":
        return PolicyMotionCfg(schedule=TURN_SCHEDULE)
    raise ValueError(f"unknown motion {name!r}; known: {sorted(MOTIONS)}")


class PolicyMotion:
    """Joint targets and PD gains from a walking policy."""

    def __init__(self, cfg: PolicyMotionCfg) -> None:
        """Load the ONNX policy and its metadata."""
        import onnxruntime as ort

        opts = ort.SessionOptions()
        opts.intra_op_num_threads = 1
        self.cfg = cfg
        self.sess = ort.InferenceSession(cfg.path, opts, providers=["CPUExecutionProvider"])
        meta = self.sess.get_modelmeta().custom_metadata_map
        if tuple(meta["joint_names"].split(",")) != G1_JOINT_NAMES:
            raise ValueError("policy joint order differs from G1_JOINT_NAMES")
        vec = lambda k: np.array([float(x) for x in meta[k].split(",")])  # noqa: E731
        self.kp, self.kd, self.q0 = vec("joint_stiffness"), vec("joint_damping"), vec("default_joint_pos")
        self.scale = float(meta["action_scale"])
        self.dt = float(meta["policy_dt"])
        self.hist = int(meta["observation_history_length"])
        self.dims = [int(float(x)) for x in meta["observation_dims"].split(",")]
        self.names = meta["observation_names"].split(",")
        self.buf: dict[str, list[np.ndarray]] = {}
        self.action = np.zeros(29)
        self.next_t = 0.0
        self.target = self.q0.copy()

    def gains(self) -> tuple[np.ndarray, np.ndarray]:
        """PD gains the policy was trained with (kp [N*m/rad], kd [N*m*s/rad]), shape [29] each."""
        return self.kp, self.kd

    def targets(self, t: float, quat: np.ndarray, gyro: np.ndarray, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
        """Return joint position targets [rad], shape [29] (a new action every ``policy_dt``)."""
        if t + 1e-9 < self.next_t:
            return self.target
        self.next_t += self.dt
        w, x, y, z = quat
        # projected gravity: R^T (0, 0, -1) for the body rotation R of quaternion (w, x, y, z)
        grav = -np.array([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)])
        cmd = self.cfg.command(t)
        terms = {
            "base_ang_vel": gyro,
            "projected_gravity": grav,
            "command": cmd,
            "joint_pos": q - self.q0,
            "joint_vel": dq,
            "actions": self.action,
        }
        parts = []
        for name, dim in zip(self.names, self.dims, strict=True):
            frames = self.buf.setdefault(name, [])
            frames.append(np.asarray(terms[name], float).reshape(dim))
            if len(frames) == 1:  # mjlab back-fills a fresh history with its first frame
                frames[:] = [frames[0]] * self.hist
            del frames[: len(frames) - self.hist]
            parts.append(np.concatenate(frames))
        obs = np.concatenate(parts).astype(np.float32)[None]
        out = self.sess.run(None, {self.sess.get_inputs()[0].name: obs})[0]
        self.action = np.asarray(out, float).reshape(-1)
        self.target = self.q0 + self.scale * self.action
        return self.target
