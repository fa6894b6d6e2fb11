# SPDX-License-Identifier: Apache-2.0
"""CPU runner of an exported student policy (onnxruntime): keeps the proprioceptive history itself.

History convention (the same as the training env, mjlab's ``CircularBuffer``): the ``history`` input is
``[batch, N, obs_dim]``, oldest frame first, and its last frame is the current observation o_t. On the first
step after construction or :meth:`OnnxPolicyRunner.reset`, the buffer is padded according to the metadata's
``history_padding``: ``"repeat_first"`` (default; mjlab back-fills a reset env's history with its first frame)
fills all N frames with that first o_t; ``"zeros"`` zero-fills the N - 1 older frames.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from gmloco.deploy.export.metadata import PolicyMetadata

__all__ = ["OnnxPolicyRunner"]


class OnnxPolicyRunner:
    """Run an exported student on CPU: ``step(o_t) -> action``, the history buffer kept per env."""

    def __init__(self, path: str | Path, num_envs: int = 1, num_threads: int = 1) -> None:
        """Load the ONNX policy and its metadata and allocate the history buffer.

        Args:
            path: Exported ``.onnx`` file (with :class:`PolicyMetadata` props).
            num_envs: Number of robots (batch rows) stepped together.
            num_threads: onnxruntime intra-op threads (1 is deterministic and fast for small MLPs).

        Raises:
            ValueError: If the model's inputs do not match the metadata.
        """
        import onnxruntime as ort

        options = ort.SessionOptions()
        options.intra_op_num_threads = num_threads
        self.session = ort.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
        self.metadata = PolicyMetadata.from_props(self.session.get_modelmeta().custom_metadata_map)
        self._check_inputs()
        self.output_names = [o.name for o in self.session.get_outputs()]
        n, d = self.metadata.history_length, self.metadata.obs_dim
        self.history = np.zeros((num_envs, n, d), dtype=np.float32)
        """History buffer ``[num_envs, N, obs_dim]``, oldest first; what the policy saw on the last step."""
        self._needs_fill = np.ones(num_envs, dtype=bool)
        self.latent: np.ndarray | None = None
        """z_hat of the last step, ``[num_envs, latent_dim]`` (None if the model has no ``latent`` output)."""
        self.eta: np.ndarray | None = None
        """Decoded stiffness psi(z_hat) of the last step, ``[num_envs, 1]`` (None if no ``eta`` output)."""

    @property
    def num_envs(self) -> int:
        """Number of robots stepped together."""
        return self.history.shape[0]

    def _check_inputs(self) -> None:
        """Check the ONNX ``obs`` / ``history`` inputs against the metadata."""
        inputs = {i.name: i.shape for i in self.session.get_inputs()}
        if set(inputs) != {"obs", "history"}:
            raise ValueError(f"Expected inputs 'obs' and 'history', got {sorted(inputs)}.")
        n, d = self.metadata.history_length, self.metadata.obs_dim
        if inputs["obs"][-1] != d or tuple(inputs["history"][1:]) != (n, d):
            raise ValueError(f"Inputs {inputs} disagree with metadata (history_length={n}, obs_dim={d}).")

    def reset(self, env_ids: Sequence[int] | np.ndarray | None = None) -> None:
        """Forget the history of ``env_ids`` (all if None); their next step pads it as documented above."""
        if env_ids is None:
            self._needs_fill[:] = True
        else:
            self._needs_fill[np.asarray(env_ids)] = True

    def push(self, obs: np.ndarray) -> None:
        """Append o_t ``[num_envs, obs_dim]`` as the newest history frame, padding envs after a reset."""
        self.history[:, :-1] = self.history[:, 1:].copy()
        self.history[:, -1] = obs
        fill = self._needs_fill
        if fill.any():
            pad = obs[fill][:, None, :] if self.metadata.history_padding == "repeat_first" else 0.0
            self.history[fill, :-1] = pad
            self._needs_fill[:] = False

    def step(self, obs: np.ndarray) -> np.ndarray:
        """Push o_t and return the action ``[num_envs, num_actions]`` (``[num_actions]`` for a 1-D ``obs``).

        Args:
            obs: Current observation frame, ``[num_envs, obs_dim]`` or ``[obs_dim]`` when ``num_envs == 1``,
                built and scaled as in training (see the metadata's observation layout).
        """
        single = np.ndim(obs) == 1
        obs2 = np.asarray(obs, dtype=np.float32).reshape(self.num_envs, self.metadata.obs_dim)
        self.push(obs2)
        results = self.session.run(None, {"obs": obs2, "history": self.history})
        outputs = {name: np.asarray(r) for name, r in zip(self.output_names, results, strict=True)}
        self.latent, self.eta = outputs.get("latent"), outputs.get("eta")
        actions = outputs[self.output_names[0]]
        return actions[0] if single else actions

    def joint_targets(self, actions: np.ndarray) -> np.ndarray:
        """Return joint-position targets q_0 + action_scale * action [rad], in ``metadata.joint_names`` order."""
        q0 = np.asarray(self.metadata.default_joint_pos, dtype=np.float32)
        return q0 + np.asarray(self.metadata.action_scale, dtype=np.float32) * actions
