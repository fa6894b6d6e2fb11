# SPDX-License-Identifier: Apache-2.0
"""Several recordings of one robot as one residual problem: their shooting segments stacked.

Each recording keeps its own replayer, noise floor, signal weights, time blocks and held-out split; the stack
concatenates their segments, so screening, fits and decisions run on it unchanged and a fitted effect must
explain every recording at once. Floors and weights are then per segment, shape [S, 1, N_CHANNELS].
"""

from __future__ import annotations

import numpy as np

from gmloco.deploy.mismatch.contract import ContractIssue
from gmloco.deploy.mismatch.problem import Problem
from gmloco.deploy.mismatch.recording import Recording

__all__ = ["StackedProblem", "check_same_robot"]

_DEFAULT_ROBOT = "unitree_g1_29dof"
"""Robot of a recording whose metadata names none (the schema's default)."""


def check_same_robot(recs: list[Recording]) -> list[ContractIssue]:
    """Contract errors that keep recordings out of one diagnosis: another robot, joint order or sample rate."""
    issues, ref = [], recs[0]
    robot0 = ref.meta.get("robot", _DEFAULT_ROBOT)
    for i, r in enumerate(recs[1:], 1):
        where = f"recording {i} ({r.meta.get('path', '?')}) vs recording 0 ({ref.meta.get('path', '?')})"
        robot = r.meta.get("robot", _DEFAULT_ROBOT)
        if robot != robot0:
            issues.append(ContractIssue("same_robot", "error", f"{where}: robot {robot!r} vs {robot0!r}"))
        if tuple(r.joint_names) != tuple(ref.joint_names):
            first = next(
                (k for k, (a, b) in enumerate(zip(r.joint_names, ref.joint_names, strict=False)) if a != b),
                min(len(r.joint_names), len(ref.joint_names)),
            )
            issues.append(ContractIssue("same_robot", "error", f"{where}: joint order differs from column {first}"))
        if not np.isclose(r.dt, ref.dt, rtol=1e-6):
            issues.append(
                ContractIssue("same_robot", "error", f"{where}: sample rate {1 / r.dt:.6g} Hz vs {1 / ref.dt:.6g} Hz")
            )
    return issues


class StackedProblem(Problem):
    """The segments of several :class:`Problem` s, with the attributes and methods the attribution reads."""

    def __init__(self, parts: list[Problem]) -> None:
        """Concatenate the parts' segments (all parts must share the compare points per segment)."""
        if not parts:
            raise ValueError("a stack needs at least one recording")
        if len({len(p.rp.offsets) for p in parts}) != 1:
            raise ValueError("stacked recordings need the same compare points per segment (same rate and horizon)")
        self.parts = parts
        self.rp = parts[0].rp
        """The first recording's replayer (replay settings shared by all)."""
        self.source = np.concatenate([np.full(len(p.starts), i) for i, p in enumerate(parts)])
        """Recording index of each segment, shape [S]."""
        self.starts = np.concatenate([p.starts for p in parts])
        """Start sample of each segment in its own recording, shape [S]."""
        offsets = np.cumsum([0] + [int(p.block.max()) + 1 for p in parts[:-1]])
        self.block = np.concatenate([p.block + o for p, o in zip(parts, offsets, strict=True)])
        """Time block of each segment, distinct across recordings, shape [S]."""
        self.held = np.concatenate([p.held for p in parts])
        self.train = ~self.held
        self.y = np.concatenate([p.y for p in parts])
        self.sigma = np.concatenate([np.broadcast_to(p.sigma, (len(p.starts), 1, p.sigma.size)) for p in parts])
        """Noise floor per segment and channel, shape [S, 1, N_CHANNELS]."""
        self.weight = np.concatenate([np.broadcast_to(p.weight, (len(p.starts), 1, p.weight.size)) for p in parts])
        """Signal weight per segment and channel, shape [S, 1, N_CHANNELS]."""

    @property
    def fixed(self) -> bool:
        """Whether every recording's pelvis is held (ground effects are then inert everywhere)."""
        return all(p.fixed for p in self.parts)

    def scale(self, mask: np.ndarray) -> np.ndarray:
        """``weight / sigma`` of the segments of ``mask``, shape [S', 1, N_CHANNELS]."""
        return (self.weight / self.sigma)[mask]

    def simulate(self, params: dict[str, np.ndarray], mask: np.ndarray | None = None) -> np.ndarray:
        """Simulate the segments selected by ``mask`` (all by default), each in its own recording's replayer."""
        m = np.ones(len(self.starts), bool) if mask is None else mask
        outs = [p.simulate(params, m[self.source == i]) for i, p in enumerate(self.parts) if m[self.source == i].any()]
        return np.concatenate(outs)

    def normalise(self, y_sim: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
        """Normalised residual of simulated measurements ``y_sim`` on the segments of ``mask``."""
        m = np.ones(len(self.starts), bool) if mask is None else mask
        return (self.y[m] - y_sim) / self.sigma[m] * self.weight[m]

    def resid(self, params: dict[str, np.ndarray], mask: np.ndarray | None = None) -> np.ndarray:
        """Normalised residual on the selected segments, shape [S', P, N_CHANNELS]."""
        return self.normalise(self.simulate(params, mask), mask)
