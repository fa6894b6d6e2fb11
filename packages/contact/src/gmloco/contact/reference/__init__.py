# SPDX-License-Identifier: Apache-2.0
"""Float64 numpy reference of every contact model, independent of the Warp kernels.

The kernels are tested against these functions on the CPU device. Conventions (spec section 0): world z up,
gravity direction g_hat = (0, 0, -1), outward unit normals (body -> medium), depth measured vertically below
the free surface, forces are those of the medium on the body [N].
"""

from gmloco.contact.materials import xi_n
from gmloco.contact.reference.cone import (
    ConeParams,
    ConeState,
    cone_flat_area,
    cone_multi_quasi_static_force,
    cone_quasi_static_force,
    cone_step,
)
from gmloco.contact.reference.rft2d import heuristic_rft_forces, rft2d_alpha, rft2d_angles
from gmloco.contact.reference.rft3d import (
    advance_stick_anchors,
    foot_wrench,
    rft3d_alpha,
    rft3d_forces,
    rft3d_generic,
    rft3d_generic_angles,
    rft3d_unloading_forces,
)

__all__ = [
    "ConeParams",
    "ConeState",
    "advance_stick_anchors",
    "cone_flat_area",
    "cone_multi_quasi_static_force",
    "cone_quasi_static_force",
    "cone_step",
    "foot_wrench",
    "heuristic_rft_forces",
    "rft2d_alpha",
    "rft2d_angles",
    "rft3d_alpha",
    "rft3d_forces",
    "rft3d_generic",
    "rft3d_generic_angles",
    "rft3d_unloading_forces",
    "xi_n",
]
