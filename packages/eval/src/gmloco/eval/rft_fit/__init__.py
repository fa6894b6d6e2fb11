# SPDX-License-Identifier: Apache-2.0
"""3D-RFT coefficients fitted from MPM plate intrusions (spec section 8)."""

from gmloco.eval.rft_fit.fit import (
    RftFitResult,
    fit_rft3d_coeffs,
    generic_from_coeffs,
    rft3d_design_matrix,
    save_rft3d_coeffs,
)
from gmloco.eval.rft_fit.plate import PlateIntrusionCfg, PlateRun, run_plate_intrusion
from gmloco.eval.rft_fit.run import RftFitCfg, plate_directions, rft_fit_smoke_cfg, run, steady_generic

__all__ = [
    "PlateIntrusionCfg",
    "PlateRun",
    "RftFitCfg",
    "RftFitResult",
    "fit_rft3d_coeffs",
    "generic_from_coeffs",
    "plate_directions",
    "rft3d_design_matrix",
    "rft_fit_smoke_cfg",
    "run",
    "run_plate_intrusion",
    "save_rft3d_coeffs",
    "steady_generic",
]
