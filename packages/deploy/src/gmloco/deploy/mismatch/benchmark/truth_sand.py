# SPDX-License-Identifier: Apache-2.0
"""Sand ground of the truth simulator: the project's float64 3D-RFT reference with the terrain effects injected.

Independent of the tool's sand (:mod:`gmloco.deploy.mismatch.sand`) and terrain laws
(:mod:`gmloco.deploy.mismatch.terrain`): the forces come from ``gmloco.contact.reference``
(``rft3d_unloading_forces``, ``advance_stick_anchors``) on a finer 7 x 7 sole collider, every cell with its own
velocity direction and its crater memory kept over the whole episode; the effects enter here:

* ``terrain.stiffness_scale``: the medium's critical density is scaled, ``rho_c (1 + zeta)`` (xi_n is linear in
  rho_c, PNAS 2023 eq. 4);
* ``terrain.depth_hardening``: each cell force is scaled by ``1 + kappa depth``;
* ``terrain.rate_drag``: ``rho_drag A v_z^2`` upward on intruding cells;
* ``terrain.cohesion``: a suction ``c A tanh(depth / 1 mm)`` downward on submerged cells.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gmloco.deploy.mismatch.benchmark.truth import TruthEffect

__all__ = ["TruthSand"]


class TruthSand:
    """3D-RFT sand under both feet of the truth robot, with one hidden terrain effect (or none)."""

    def __init__(self, e: TruthEffect, material: str = "dry_sand", resolution: int = 7) -> None:
        """Collider, medium and effect parameters."""
        # here, not at the top: gmloco.contact pulls Warp; deploy's light core imports without it
        from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, g1_foot_collider

        col = g1_foot_collider("sole", resolution)
        self.pb, self.nb, self.area = (np.asarray(a, float) for a in (col.points, col.normals, col.areas))
        self.mat = MATERIAL_PRESETS[material]
        self.rest = ContactRFT3DCfg()
        val = float(next(iter(e.params.values()))[0]) if e.id.startswith("terrain.") else 0.0
        self.zeta = val if e.id == "terrain.stiffness_scale" else 0.0
        self.kappa = val if e.id == "terrain.depth_hardening" else 0.0
        self.drag = val if e.id == "terrain.rate_drag" else 0.0
        self.cohesion = val if e.id == "terrain.cohesion" else 0.0
        m = len(self.pb)
        self.zmax = [np.zeros(m), np.zeros(m)]
        self.anchor = [np.zeros((m, 3)), np.zeros((m, 3))]

    def apply(self, model: Any, data: Any, feet: list[int]) -> None:
        """Add the sand wrench of both feet to ``data.xfrc_applied`` and advance the crater state."""
        import mujoco

        # gmloco.contact pulls Warp, as above
        from gmloco.contact.reference import advance_stick_anchors, rft3d_unloading_forces

        r = self.rest
        for i, b in enumerate(feet):
            rot = data.xmat[b].reshape(3, 3)
            arm = self.pb @ rot.T
            pts, nrm = data.xpos[b] + arm, self.nb @ rot.T
            v6 = np.zeros(6)
            mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, b, v6, 0)
            vel = v6[3:] + np.cross(v6[:3], arm)
            f = rft3d_unloading_forces(
                pts,
                nrm,
                vel,
                self.area,
                self.zmax[i],
                rho_c=self.mat.rho_c * (1.0 + self.zeta),
                mu_int=self.mat.mu_int,
                mu_surf=self.mat.mu_surf,
                ratio=r.unloading_ratio,
                tangential_damping=r.tangential_damping,
                damping=r.unloading_damping,
                unloading_speed=r.unloading_speed,
                anchors=self.anchor[i],
                stick_distance=r.stick_distance,
            )
            depth = -pts[:, 2]
            wet = depth > 0.0
            f = f * (1.0 + self.kappa * np.clip(depth, 0.0, None))[:, None]
            f[:, 2] += self.drag * self.area * np.square(np.minimum(vel[:, 2], 0.0)) * wet
            f[:, 2] -= self.cohesion * self.area * np.tanh(np.clip(depth, 0.0, None) / 0.001)
            self.anchor[i] = advance_stick_anchors(pts, nrm, self.anchor[i], self.zmax[i], r.stick_distance)
            self.zmax[i] = np.where(wet, np.maximum(self.zmax[i], depth), 0.0)
            data.xfrc_applied[b, :3] += f.sum(0)
            data.xfrc_applied[b, 3:] += np.cross(pts - data.xipos[b], f).sum(0)
