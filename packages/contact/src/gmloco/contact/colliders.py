# SPDX-License-Identifier: Apache-2.0
"""Box colliders sampled as surface point sets: cell-centred points with exact areas and outward normals."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

__all__ = [
    "G1_FOOT_X",
    "G1_FOOT_Y",
    "G1_FOOT_Z",
    "ColliderBoxCfg",
    "ColliderPoints",
    "box_collider",
    "g1_foot_box_cfg",
    "g1_foot_collider",
]

G1_FOOT_X: tuple[float, float] = (-0.065, 0.141)
"""G1 foot box extent along x of ``*_ankle_roll_link`` [m] (GM-Loco collider, spec 4)."""
G1_FOOT_Y: tuple[float, float] = (-0.0368, 0.0368)
"""G1 foot box extent along y [m]."""
G1_FOOT_Z: tuple[float, float] = (-0.03539, 0.0)
"""G1 foot box extent along z [m]; the sole is the z = -0.03539 face."""


@dataclass(frozen=True)
class ColliderBoxCfg:
    """An axis-aligned box in a body frame, sampled on its sole or on all six faces."""

    x_range: tuple[float, float] = G1_FOOT_X
    """Box extent along body x [m] (min, max)."""
    y_range: tuple[float, float] = G1_FOOT_Y
    """Box extent along body y [m] (min, max)."""
    z_range: tuple[float, float] = G1_FOOT_Z
    """Box extent along body z [m] (min, max); the sole is the face at z_range[0]."""
    faces: Literal["sole", "box"] = "sole"
    """``"sole"``: the -z face only; ``"box"``: all six faces."""
    resolution: int | tuple[int, int, int] = 5
    """Cells per edge: an int n gives n x n points per face, a tuple gives (n_x, n_y, n_z) cells along the axes."""

    def __post_init__(self) -> None:
        """Reject empty boxes and non-positive resolutions."""
        for name, (lo, hi) in (("x_range", self.x_range), ("y_range", self.y_range), ("z_range", self.z_range)):
            if not hi > lo:
                raise ValueError(f"{name}={(lo, hi)} [m]: need max > min")
        if min(self.counts) < 1:
            raise ValueError(f"resolution={self.resolution}: need >= 1 cell per edge")
        if self.faces not in ("sole", "box"):
            raise ValueError(f"faces={self.faces!r}: use 'sole' (the -z face) or 'box' (all six faces)")

    @property
    def counts(self) -> tuple[int, int, int]:
        """Cells along (x, y, z)."""
        r = self.resolution
        return (r, r, r) if isinstance(r, int) else (int(r[0]), int(r[1]), int(r[2]))

    @property
    def sole_center(self) -> np.ndarray:
        """Centre of the sole face in the body frame [m], [3]."""
        return np.array([np.mean(self.x_range), np.mean(self.y_range), self.z_range[0]])

    @property
    def sole_hydraulic_radius(self) -> float:
        """Hydraulic radius 2A/P = l_x l_y / (l_x + l_y) of the sole [m] (GM-Loco cone convention)."""
        lx, ly = np.diff(self.x_range)[0], np.diff(self.y_range)[0]
        return float(lx * ly / (lx + ly))


@dataclass(frozen=True)
class ColliderPoints:
    """Surface elements of a collider in its body frame, float64."""

    points: np.ndarray
    """Cell centres [m], [P, 3]."""
    normals: np.ndarray
    """Outward unit normals (body -> medium), [P, 3]."""
    areas: np.ndarray
    """Cell areas [m^2], [P]; they sum exactly to the sampled faces' area."""

    @property
    def num_points(self) -> int:
        """Number of elements P."""
        return len(self.areas)


def _face(axis: int, side: int, lo: np.ndarray, hi: np.ndarray, counts: tuple[int, int, int]) -> ColliderPoints:
    """Sample the face of the box normal to ``axis`` on ``side`` (-1 or +1) at cell centres."""
    u, w = [a for a in range(3) if a != axis]
    edges_u = np.linspace(lo[u], hi[u], counts[u] + 1)
    edges_w = np.linspace(lo[w], hi[w], counts[w] + 1)
    cu, cw = np.meshgrid(0.5 * (edges_u[1:] + edges_u[:-1]), 0.5 * (edges_w[1:] + edges_w[:-1]), indexing="ij")
    pts = np.zeros((cu.size, 3))
    pts[:, u], pts[:, w] = cu.ravel(), cw.ravel()
    pts[:, axis] = hi[axis] if side > 0 else lo[axis]
    normals = np.zeros_like(pts)
    normals[:, axis] = float(side)
    du, dw = np.meshgrid(np.diff(edges_u), np.diff(edges_w), indexing="ij")
    return ColliderPoints(pts, normals, (du * dw).ravel())


def box_collider(cfg: ColliderBoxCfg) -> ColliderPoints:
    """Sample a box collider: the sole (-z face) first, then (box) +z, -x, +x, -y, +y faces."""
    lo = np.array([cfg.x_range[0], cfg.y_range[0], cfg.z_range[0]], dtype=np.float64)
    hi = np.array([cfg.x_range[1], cfg.y_range[1], cfg.z_range[1]], dtype=np.float64)
    faces = [(2, -1)] if cfg.faces == "sole" else [(2, -1), (2, 1), (0, -1), (0, 1), (1, -1), (1, 1)]
    parts = [_face(axis, side, lo, hi, cfg.counts) for axis, side in faces]
    return ColliderPoints(
        np.concatenate([p.points for p in parts]),
        np.concatenate([p.normals for p in parts]),
        np.concatenate([p.areas for p in parts]),
    )


def g1_foot_box_cfg(faces: Literal["sole", "box"] = "sole", resolution: int = 5) -> ColliderBoxCfg:
    """Return the G1 foot box of GM-Loco in the ``ankle_roll_link`` frame (spec 4)."""
    return ColliderBoxCfg(faces=faces, resolution=resolution)


def g1_foot_collider(faces: Literal["sole", "box"] = "sole", resolution: int = 5) -> ColliderPoints:
    """Return the G1 foot collider points in the ``ankle_roll_link`` frame (sole area 0.2060 x 0.0736 m^2)."""
    return box_collider(g1_foot_box_cfg(faces, resolution))
