# SPDX-License-Identifier: Apache-2.0
"""Pluggable ground contact for the simulator-side recorder.

A ground model adds foot forces each physics step and reports per-foot contact truth for the privileged
``/sim/foot_contact`` topic. :class:`RigidGround` uses MuJoCo's own contacts with the floor plane. A granular
model (``gmloco.contact``'s numpy reference RFT, once it lands) implements the same protocol: build the scene
with ``G1SceneCfg(floor=False)`` and write the sand wrench into ``data.xfrc_applied`` of the ankle-roll links in
:meth:`GroundContact.apply`, reporting intrusion depth as ``sinkage``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from gmloco.deploy.g1 import G1_FEET

__all__ = ["GroundContact", "RigidGround", "RigidGroundCfg"]


class GroundContact(Protocol):
    """What the recorder needs from a ground model."""

    material: str
    """Metadata ``material`` label."""
    contact_model: str
    """Metadata ``contact_model`` label."""

    def apply(self, model: Any, data: Any) -> None:
        """Add this step's ground wrench to ``data.xfrc_applied`` (no-op for MuJoCo-native contact)."""
        ...

    def foot_state(self, model: Any, data: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return contact flags [2], ground reaction forces in world [N] [2, 3], sinkage [m] [2] (left, right)."""
        ...


@dataclass
class RigidGroundCfg:
    """Settings of :class:`RigidGround`."""

    contact_threshold: float = 1.0
    """Normal force above which a foot counts as in contact [N]."""


class RigidGround:
    """MuJoCo's rigid floor-plane contact; forces read back with ``mj_contactForce``."""

    material = "rigid"
    contact_model = "rigid"

    def __init__(self, cfg: RigidGroundCfg, model: Any) -> None:
        """Map foot geoms to feet."""
        self.cfg = cfg
        self._foot_of_geom = {}
        for g in range(model.ngeom):
            name = model.geom(g).name
            for k, foot in enumerate(G1_FEET):
                if name.startswith(f"{foot}_foot"):
                    self._foot_of_geom[g] = k

    def apply(self, model: Any, data: Any) -> None:
        """Nothing to add: MuJoCo resolves rigid contact itself."""

    def foot_state(self, model: Any, data: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Sum contact forces per foot (world frame)."""
        import mujoco

        force = np.zeros((len(G1_FEET), 3))
        f6 = np.zeros(6)
        for i in range(data.ncon):
            c = data.contact[i]
            k = self._foot_of_geom.get(c.geom1, self._foot_of_geom.get(c.geom2))
            if k is None:
                continue
            mujoco.mj_contactForce(model, data, i, f6)
            # Contact frame rows are the normal and tangents; force on geom2 from geom1 is +f.
            fw = c.frame.reshape(3, 3).T @ f6[:3]
            force[k] += fw if c.geom2 in self._foot_of_geom else -fw
        in_contact = force[:, 2] > self.cfg.contact_threshold
        return in_contact, force, np.zeros(len(G1_FEET))
