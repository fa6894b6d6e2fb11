# SPDX-License-Identifier: Apache-2.0
"""CPU runner of an exported policy (onnxruntime) that builds its observation from the file's metadata alone.

The runner reads :class:`~gmloco.deploy.export.PolicyMetadata` from the ONNX file (and refuses a file without
it), turns raw observation terms into a frame o_t (each term clipped, then scaled, concatenated in the
metadata's order), keeps the last N frames oldest first, and feeds them in the file's input layout: ``obs`` +
``history`` ``[batch, N, obs_dim]`` for a student, or one ``[batch, N * obs_dim]`` input stacked term by term for
an mjlab actor export. On the first step after construction or :meth:`OnnxPolicyRunner.reset` the older frames are
padded as the metadata's ``history_padding`` says (``"repeat_first"``: mjlab back-fills with that first frame).

A policy trained with ``yaw_command="yaw_target"`` observes a heading-corrected yaw rate: given raw terms, the
runner replaces the last entry of the ``command`` term (w_z) by the rule of :mod:`gmloco.deploy.export.yaw_target`,
which needs the robots' heading at every step (``step(terms, heading=...)``); ``heading_envs`` policies see the
command as given.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.export.metadata import PolicyMetadata, PolicyMetadataError
from gmloco.deploy.export.yaw_target import YawTargetCfg, YawTargetCommand

__all__ = ["OnnxPolicyRunner"]


def _session(path: str | Path, num_threads: int) -> Any:
    """Return an onnxruntime session with the batch axis of every input and output made symbolic."""
    import onnx
    import onnxruntime as ort

    model = onnx.load(str(path))
    for value in [*model.graph.input, *model.graph.output]:
        dims = value.type.tensor_type.shape.dim
        if len(dims) > 0 and dims[0].HasField("dim_value"):  # mjlab exports batch 1
            dims[0].dim_param = "batch"
    options = ort.SessionOptions()
    options.intra_op_num_threads = num_threads
    return ort.InferenceSession(model.SerializeToString(), options, providers=["CPUExecutionProvider"])


class OnnxPolicyRunner:
    """Run an exported policy on CPU: ``step(terms or o_t) -> action``, the history kept per env."""

    def __init__(self, path: str | Path, num_envs: int = 1, num_threads: int = 1) -> None:
        """Load the ONNX policy and its metadata and allocate the history buffer.

        Args:
            path: Exported ``.onnx`` file carrying :class:`PolicyMetadata`.
            num_envs: Number of robots (batch rows) stepped together.
            num_threads: onnxruntime intra-op threads (1 is deterministic and fast for small MLPs).

        Raises:
            PolicyMetadataError: If the metadata is missing, of an unknown version, or disagrees with the inputs.
        """
        self.metadata = self._read(path)
        self.session = _session(path, num_threads)
        self.input_names = [i.name for i in self.session.get_inputs()]
        self._check_inputs()
        self.output_names = [o.name for o in self.session.get_outputs()]
        obs = self.metadata.observation
        self.history = np.zeros((num_envs, obs.history_length, obs.obs_dim), dtype=np.float32)
        """History buffer ``[num_envs, N, obs_dim]``, oldest first; what the policy saw on the last step."""
        self._needs_fill = np.ones(num_envs, dtype=bool)
        bounds = np.cumsum([0, *(t.dim for t in obs.terms)]).tolist()
        self._slices = [slice(a, b) for a, b in pairwise(bounds)]
        self.latent: np.ndarray | None = None
        """z_hat of the last step, ``[num_envs, latent_dim]`` (None if the model has no ``latent`` output)."""
        self.eta: np.ndarray | None = None
        """Decoded stiffness psi(z_hat) of the last step, ``[num_envs, 1]`` (None if no ``eta`` output)."""
        rule = YawTargetCfg.from_metadata(self.metadata)
        self.yaw_target = None if rule is None else YawTargetCommand(rule, num_envs)
        """Heading rule of a ``yaw_target`` policy (None: the command is observed as given)."""

    @staticmethod
    def _read(path: str | Path) -> PolicyMetadata:
        """Read the metadata with onnx (no session needed to refuse a file)."""
        from gmloco.deploy.export.metadata import read_policy_metadata

        return read_policy_metadata(path)

    @property
    def num_envs(self) -> int:
        """Number of robots stepped together."""
        return self.history.shape[0]

    def _check_inputs(self) -> None:
        """Check the ONNX inputs against the metadata's layout, history length and frame width."""
        obs = self.metadata.observation
        n, d = obs.history_length, obs.obs_dim
        shapes = {i.name: list(i.shape) for i in self.session.get_inputs()}
        if obs.layout == "frame_and_history":
            ok = set(shapes) == {"obs", "history"}
            ok = ok and shapes["obs"][-1] == d and shapes["history"][1:] == [n, d]
        else:
            ok = len(shapes) == 1 and next(iter(shapes.values()))[-1] == n * d
        if not ok:
            raise PolicyMetadataError(
                f"ONNX inputs {shapes} disagree with the metadata (layout {obs.layout!r}, history_length {n}, "
                f"obs_dim {d}); the file's metadata does not describe this network."
            )

    def frame(self, terms: Mapping[str, Any]) -> np.ndarray:
        """Build o_t ``[num_envs, obs_dim]`` from raw terms ``{name: [num_envs, dim]}``: clip, scale, concatenate.

        Raises:
            KeyError: If a term of the metadata is missing from ``terms``.
        """
        parts = []
        for term in self.metadata.observation.terms:
            if term.name not in terms:
                raise KeyError(f"observation term {term.name!r} missing (the policy needs {self.term_names})")
            x = np.asarray(terms[term.name], dtype=np.float32).reshape(self.num_envs, term.dim)
            if term.clip is not None:
                x = np.clip(x, term.clip[0], term.clip[1])
            parts.append(x * np.asarray(term.scale, dtype=np.float32))
        return np.concatenate(parts, axis=1)

    @property
    def term_names(self) -> list[str]:
        """Observation term names, in frame order."""
        return [t.name for t in self.metadata.observation.terms]

    def reset(self, env_ids: Sequence[int] | np.ndarray | None = None) -> None:
        """Forget the history of ``env_ids`` (all if None); their next step pads it as documented above."""
        if env_ids is None:
            self._needs_fill[:] = True
        else:
            self._needs_fill[np.asarray(env_ids, dtype=int)] = True
        if self.yaw_target is not None:
            self.yaw_target.reset(env_ids)

    def observed_terms(self, terms: Mapping[str, Any], heading: np.ndarray | None) -> Mapping[str, Any]:
        """Return ``terms`` with the command's w_z (its last entry) as the policy was trained to observe it.

        Args:
            terms: Raw observation terms ``{name: [num_envs, dim]}``; ``command`` holds (..., w_z [rad/s]).
            heading: Base yaw of each robot [rad], ``[num_envs]``; needed by ``yaw_target`` policies.

        Raises:
            ValueError: A ``yaw_target`` policy is stepped without ``heading``.
        """
        if self.yaw_target is None or "command" not in terms:
            return terms
        if heading is None:
            raise ValueError(
                "this policy was trained with yaw_command='yaw_target' (see gmloco-policy-info): it observes "
                "w_z + k * wrap(yaw_target - yaw), so pass the robots' heading: runner.step(terms, heading=yaw)."
            )
        cmd = np.array(terms["command"], dtype=np.float64).reshape(self.num_envs, -1)
        cmd[:, -1] = self.yaw_target.step(cmd[:, -1], heading)
        return {**terms, "command": cmd}

    def push(self, obs: np.ndarray) -> None:
        """Append o_t ``[num_envs, obs_dim]`` as the newest history frame, padding envs after a reset."""
        self.history[:, :-1] = self.history[:, 1:].copy()
        self.history[:, -1] = obs
        fill = self._needs_fill
        if fill.any():
            pad = obs[fill][:, None, :] if self.metadata.observation.history_padding == "repeat_first" else 0.0
            self.history[fill, :-1] = pad
            self._needs_fill[:] = False

    def network_inputs(self) -> dict[str, np.ndarray]:
        """Return the ONNX inputs for the current history in the file's layout."""
        if self.metadata.observation.layout == "frame_and_history":
            return {"obs": self.history[:, -1].copy(), "history": self.history}
        stacked = [self.history[:, :, s].reshape(self.num_envs, -1) for s in self._slices]  # term-major, oldest first
        return {self.input_names[0]: np.concatenate(stacked, axis=1)}

    def step(self, obs: np.ndarray | Mapping[str, Any], heading: np.ndarray | None = None) -> np.ndarray:
        """Push o_t and return the action ``[num_envs, num_actions]`` (``[num_actions]`` for a 1-D ``obs``).

        Args:
            obs: Raw observation terms ``{name: [num_envs, dim]}`` (heading rule applied by
                :meth:`observed_terms`, then built into o_t by :meth:`frame`), or o_t itself, ``[num_envs, obs_dim]``
                or ``[obs_dim]`` when ``num_envs == 1``, already corrected, clipped and scaled.
            heading: Base yaw of each robot [rad], ``[num_envs]``, with raw terms of a ``yaw_target`` policy.
        """
        if isinstance(obs, Mapping):
            single, frame = False, self.frame(self.observed_terms(obs, heading))
        else:
            single = np.ndim(obs) == 1
            frame = np.asarray(obs, dtype=np.float32).reshape(self.num_envs, self.metadata.obs_dim)
        self.push(frame)
        results = self.session.run(None, self.network_inputs())
        outputs = {name: np.asarray(r) for name, r in zip(self.output_names, results, strict=True)}
        self.latent, self.eta = outputs.get("latent"), outputs.get("eta")
        actions = outputs[self.output_names[0]]
        return actions[0] if single else actions

    def joint_targets(self, actions: np.ndarray) -> np.ndarray:
        """Return joint-position targets q_0 + action_scale * action [rad], in ``metadata.joints.names`` order."""
        joints = self.metadata.joints
        q0 = np.asarray(joints.default_pos, dtype=np.float32)
        return q0 + np.asarray(joints.action_scale, dtype=np.float32) * actions
