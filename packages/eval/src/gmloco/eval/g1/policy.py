# SPDX-License-Identifier: Apache-2.0
"""Exported policies driving the G1 MPM scene, batched over robots (onnxruntime on CPU).

Two kinds: a file with gmloco's metadata document (student ``obs`` + ``history``, or an actor whose one input
stacks each term's history oldest first), run by ``gmloco.deploy.export.OnnxPolicyRunner``; and a plain mjlab
actor export, read from mjlab's comma-joined keys. Both take one
frame of observation terms per robot, ``{name: [num_robots, dim]}``, and the robots' heading, and return actions
``[num_robots, A]``. A policy whose metadata says ``yaw_command="yaw_target"`` observes the heading-corrected yaw
rate of its training (the runner applies :mod:`gmloco.deploy.export.yaw_target` from the metadata); mjlab exports
and ``heading_envs`` policies see the command as given.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["MjlabOnnxPolicy", "PolicySpec", "StudentOnnxPolicy", "load_policy", "policy_problem"]


@dataclass(frozen=True)
class PolicySpec:
    """What the scene needs from a policy (read from ONNX metadata, or the default pose for PD-only runs)."""

    joint_names: list[str]
    """Actuated joints in action order."""
    kp: np.ndarray
    """PD stiffness [N m/rad], [A]."""
    kd: np.ndarray
    """PD damping [N m s/rad], [A]."""
    default_joint_pos: np.ndarray
    """q_0 [rad], [A]."""
    action_scale: np.ndarray
    """q* = q_0 + action_scale a [rad], [A]."""
    policy_dt: float = 0.02
    """Policy period [s]."""


def _batched_session(path: str | Path, num_threads: int) -> Any:
    """Return an onnxruntime session of the model with its batch dimension made symbolic (mjlab exports batch 1)."""
    import onnx
    import onnxruntime as ort

    model = onnx.load(str(path))
    for value in [*model.graph.input, *model.graph.output]:
        dims = value.type.tensor_type.shape.dim
        if len(dims) > 0:
            dims[0].ClearField("dim_value")
            dims[0].dim_param = "batch"
    options = ort.SessionOptions()
    options.intra_op_num_threads = num_threads
    return ort.InferenceSession(model.SerializeToString(), options, providers=["CPUExecutionProvider"])


class MjlabOnnxPolicy:
    """An mjlab-exported actor (single ``obs`` input) for ``num_robots`` robots with per-robot histories."""

    def __init__(self, path: str | Path, num_robots: int = 1, num_threads: int = 1) -> None:
        """Load the model (batch dimension made symbolic) and parse its comma-joined metadata."""
        self.session = _batched_session(path, num_threads)
        meta = self.session.get_modelmeta().custom_metadata_map
        floats = lambda key: np.array([float(v) for v in meta[key].split(",")])  # noqa: E731
        self.joint_names = meta["joint_names"].split(",")
        self.action_joint_names = meta.get("action_joint_names", meta["joint_names"]).split(",")
        self.term_names = meta["observation_names"].split(",")
        self.term_dims = [round(v) for v in floats("observation_dims")]
        self.term_history = [round(v) for v in floats("observation_terms_history_length")]
        self.term_scale = floats("observation_terms_scale")
        self.obs_dim = int(meta["observation_dim"])
        if sum(d * h for d, h in zip(self.term_dims, self.term_history, strict=True)) != self.obs_dim:
            raise ValueError("observation layout in the metadata does not add up to observation_dim")
        scale = floats("action_scale")
        by_name = dict(zip(self.joint_names, range(len(self.joint_names)), strict=True))
        idx = [by_name[n] for n in self.action_joint_names]
        self.spec = PolicySpec(
            joint_names=self.action_joint_names,
            kp=floats("joint_stiffness")[idx],
            kd=floats("joint_damping")[idx],
            default_joint_pos=floats("default_joint_pos")[idx],
            action_scale=np.broadcast_to(scale, (len(idx),)).copy(),
            policy_dt=float(meta.get("policy_dt", 0.02)),
        )
        self.input_name = self.session.get_inputs()[0].name
        self.num_robots = num_robots
        self._hist: list[np.ndarray] | None = None
        self._fresh: list[int] = []

    def reset(self, robots: Sequence[int] | None = None) -> None:
        """Forget the histories of ``robots`` (all if None); their next frame is back-filled, as mjlab does."""
        if robots is None:
            self._hist, self._fresh = None, []
        else:
            self._fresh = sorted(set(self._fresh) | {int(r) for r in robots})

    def act(self, terms: dict[str, np.ndarray], heading: np.ndarray | None = None) -> np.ndarray:
        """Push one frame of observation terms ``{name: [R, dim]}`` and return the actions [R, A].

        ``heading`` [rad] is not used: mjlab's velocity task observes the commanded w_z as given.
        """
        frames = [
            np.asarray(terms[n], dtype=np.float32).reshape(self.num_robots, -1) * s
            for n, s in zip(self.term_names, self.term_scale, strict=True)
        ]
        if self._hist is None:
            self._hist = [np.repeat(f[:, None], h, axis=1) for f, h in zip(frames, self.term_history, strict=True)]
        else:
            self._hist = [
                np.concatenate([b[:, 1:], f[:, None]], axis=1) for b, f in zip(self._hist, frames, strict=True)
            ]
            for b, f in zip(self._hist, frames, strict=True):
                b[self._fresh] = f[self._fresh, None]
        self._fresh = []
        obs = np.concatenate([b.reshape(self.num_robots, -1) for b in self._hist], axis=1).astype(np.float32)
        return np.asarray(self.session.run(None, {self.input_name: obs})[0])


class StudentOnnxPolicy:
    """A policy carrying gmloco's metadata (student or actor), run by ``OnnxPolicyRunner`` for ``num_robots`` robots."""

    def __init__(self, path: str | Path, num_robots: int = 1) -> None:
        """Load the runner; check that the observation terms are ones the scene provides."""
        # here, not at the top: gmloco.deploy.export pulls onnx (and the runner onnxruntime)
        from gmloco.deploy.export import OnnxPolicyRunner

        self.runner = OnnxPolicyRunner(path, num_envs=num_robots)
        meta = self.runner.metadata
        known = {"base_ang_vel", "projected_gravity", "command", "joint_pos", "joint_vel", "actions"}
        if not set(self.runner.term_names) <= known:
            raise ValueError(f"unsupported observation terms {sorted(set(self.runner.term_names) - known)}")
        self.meta = meta
        self.num_robots = num_robots
        joints = meta.joints
        self.spec = PolicySpec(
            joint_names=list(joints.names),
            kp=np.asarray(joints.stiffness, dtype=np.float64),
            kd=np.asarray(joints.damping, dtype=np.float64),
            default_joint_pos=np.asarray(joints.default_pos, dtype=np.float64),
            action_scale=np.asarray(joints.action_scale, dtype=np.float64),
            policy_dt=float(meta.timing.policy_dt),
        )

    def reset(self, robots: Sequence[int] | None = None) -> None:
        """Forget the histories of ``robots`` (all if None)."""
        self.runner.reset(None if robots is None else list(robots))

    def act(self, terms: dict[str, np.ndarray], heading: np.ndarray | None = None) -> np.ndarray:
        """Build o_t from the terms ``{name: [R, dim]}`` by the metadata (heading rule, clip, scale, order).

        Args:
            terms: Raw observation terms, ``command`` = (v_x, v_y, w_z) as commanded.
            heading: Base yaw of each robot [rad], [R]; a ``yaw_target`` policy needs it.

        Returns:
            Actions [R, A].
        """
        return np.asarray(self.runner.step(terms, heading=heading)).reshape(self.num_robots, -1)


def policy_problem(path: str | Path) -> str | None:
    """Why ``path`` cannot be loaded as an ONNX policy (one sentence), or None when it can."""
    import onnx

    p = Path(path)
    if not p.is_file():
        return f"'{p}' {'is a directory' if p.is_dir() else 'does not exist'}: pass an exported policy.onnx"
    try:
        model = onnx.load(str(p), load_external_data=False)
    except Exception as exc:  # protobuf's DecodeError and friends: not an ONNX file
        return f"'{p}' is not an ONNX model ({type(exc).__name__}): pass an exported policy.onnx"
    if not model.graph.node:  # an empty or foreign protobuf decodes to an empty model
        return f"'{p}' is not an ONNX model (no graph): pass an exported policy.onnx"
    return None


def load_policy(path: str | Path, num_robots: int = 1) -> MjlabOnnxPolicy | StudentOnnxPolicy:
    """Return the metadata-driven runner (gmloco's document present) or mjlab's actor export for ``num_robots``.

    Raises:
        PolicyMetadataError: If the file has neither gmloco's document nor mjlab's keys (e.g. version-1 metadata).
    """
    # onnx, and gmloco.deploy.export that pulls it, load only when a policy file is read
    import onnx

    from gmloco.deploy.export import METADATA_KEY, PolicyMetadata

    props = {p.key: p.value for p in onnx.load(str(path), load_external_data=False).metadata_props}
    if METADATA_KEY in props:
        return StudentOnnxPolicy(path, num_robots)
    if "observation_dims" not in props or "format" in props:
        PolicyMetadata.from_props(props)  # raises, saying what the file carries instead
    return MjlabOnnxPolicy(path, num_robots)
